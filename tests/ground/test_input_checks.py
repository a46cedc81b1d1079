"""The checks behind the one-line refusals: lists of numbers, scheduler addresses, UTF-8
files, normal stresses; the settings classes' tables of ranges; and the paper report's word
on laboratory data."""

from __future__ import annotations

from dataclasses import dataclass, fields

import pytest

from poro2d.cli.shear import parse_stresses
from poro2d.config import check_number_list
from poro2d.criterion.settings import CRITERION_RANGES, CriterionSettings
from poro2d.errors import InputError, Integer, OneOf, Real, check_fields
from poro2d.execute import cluster_options, dask_cluster
from poro2d.io_utils import read_utf8, text_position
from poro2d.shear.settings import SHEAR_RANGES, ShearSettings
from poro2d.specimen.compaction import SPECIMEN_RANGES, SpecimenSpec
from poro2d.sweep.density import check_mus


@pytest.mark.parametrize(
    ("value", "why"),
    [
        (0.1, "= 0.1 is invalid"),
        (True, "= True is invalid"),
        ("abc", "= 'abc' is invalid"),
        ([], "= [] is invalid"),
        ([0.1], "= [0.1] is invalid"),
        ([0.0, "0.5"], "'0.5' is not a number"),
        ([0.0, True], "True is not a number"),
        ([0.05, 0.5, 5.5], "5.5 is out of range"),
        ([0.0, 1e6], "1000000.0 is out of range"),
        ([-0.1, 0.5], "-0.1 is out of range"),
        ([0.0, float("nan")], "nan is out of range"),
        ([0.0, float("inf")], "inf is out of range"),
        ([0.5, 0.1], "strictly increasing"),
        ([0.1, 0.1], "strictly increasing"),
        ({"a": 1}, "is invalid"),
    ],
)
def test_preparation_frictions(value, why):
    with pytest.raises(InputError, match="relation.mu_prep") as exc:
        check_mus(value, "relation.mu_prep")
    assert why in str(exc.value)
    assert "a list of 2 to 20 preparation frictions in [0, 5]" in str(exc.value)


def test_frictions_accepted_as_floats():
    assert check_mus((0, 0.05, 1)) == [0.0, 0.05, 1.0]
    assert check_mus((0, 1, 5)) == [0.0, 1.0, 5.0]  # up to MU_PREP_MAX, the loosest preparation measured
    assert check_number_list("x", [0.3, 0.4], 0.3, 0.4) == [0.3, 0.4]
    with pytest.raises(InputError, match=r"in \(1, 20\]"):
        check_number_list("cu", [1.0, 2.0], 1.0, 20.0, lo_open=True)


@pytest.mark.parametrize(
    "address",
    ["notanaddress", "", "tcp://", "http://host:8786", "tcp://host:0", "tcp://host:x", "host:8786/a"],
)
def test_scheduler_address_form(address):
    with pytest.raises(InputError, match="--scheduler"):
        cluster_options.check_scheduler_address(address)


def test_scheduler_address_accepted():
    assert cluster_options.check_scheduler_address("localhost:8786") == "tcp://localhost:8786"
    assert cluster_options.check_scheduler_address("tls://10.0.0.2:8786") == "tls://10.0.0.2:8786"
    assert cluster_options.check_scheduler_address("tcp://[::1]:8786") == "tcp://[::1]:8786"


def test_unreachable_scheduler_is_one_line(monkeypatch):
    import distributed

    monkeypatch.setattr(dask_cluster, "CONNECT_TIMEOUT_S", 1)
    timeouts = []
    client = distributed.Client

    def recorded(address, timeout):
        timeouts.append(timeout)
        return client(address, timeout=timeout)

    monkeypatch.setattr(distributed, "Client", recorded)
    with pytest.raises(InputError) as exc:
        dask_cluster.connect("tcp://127.0.0.1:1")  # nothing listens on port 1
    msg = str(exc.value)
    assert msg.startswith("--scheduler = 'tcp://127.0.0.1:1' is invalid")
    assert "answers within 1 s" in msg and "\n" not in msg
    assert timeouts == ["1s"]  # the short timeout, not distributed's 30 s


def test_workers_bounded():
    with pytest.raises(InputError, match="--workers"):
        cluster_options.check_cluster_options(None, cluster_options.max_workers() + 1)
    with pytest.raises(InputError, match="--workers = 1 is invalid; allowed: nothing with --scheduler"):
        cluster_options.check_cluster_options("tcp://h:1", 1)
    cluster_options.check_cluster_options(None, cluster_options.max_workers())


def test_non_utf8_located(tmp_path):
    f = tmp_path / "x.txt"
    f.write_bytes(b"abc\ndef\xffg\n")
    with pytest.raises(InputError, match=r"byte 0xff at line 2, column 4 is not UTF-8") as exc:
        read_utf8("thing", f, "UTF-8 text")
    assert str(f) in str(exc.value)
    assert text_position(b"a\nb\nc", 4) == (3, 1)
    f.write_text("é ok\n", encoding="utf-8")
    assert read_utf8("thing", f, "UTF-8 text") == "é ok\n"


@pytest.mark.parametrize(
    "text", ["50,,100", "50,", ",50", "1e9", "1e-9", "0.5", "1001", "nan", "inf", "-50", ""]
)
def test_normal_stresses_refused(text):
    with pytest.raises(InputError, match="--normal-stress"):
        parse_stresses(text)


def test_normal_stresses_at_the_ends():
    assert parse_stresses(" 1, 50 ,1000") == [1.0, 50.0, 1000.0]


def _report_text(tmp_path, **summary) -> str:
    import json
    from pathlib import Path

    from poro2d.criterion.result import CriterionOutputs, CriterionResult
    from poro2d.paper import PAPER, PaperSummary
    from poro2d.report.document import to_markdown
    from poro2d.report.paper_report import build_blocks

    base = dict(quick=False, seed=0, conversions={"methods": []}, criterion={}, replicate_specimens=None,
                shear=None, paper=PAPER, timings={}, provenance={})  # fmt: skip
    stored = Path(__file__).parents[1] / "data" / "before_typed_results" / "criterion_result.json"
    crit = CriterionOutputs(CriterionResult.from_dict(json.loads(stored.read_text())))
    return to_markdown(build_blocks(tmp_path, PaperSummary(**dict(base, **summary)), crit), tmp_path)


def test_report_names_the_lab_data_given(tmp_path):
    lab = {"source": "mylab.csv", "kind": "peaks", "peaks": [{"normal_stress_kpa": 50.0}] * 2}
    assert "pass them with --lab" in _report_text(tmp_path)
    with_lab = _report_text(tmp_path, lab=lab, shear={"tests": []})
    assert "pass them with --lab" not in with_lab
    assert "laboratory peaks from mylab.csv (2 peak(s)) are drawn beside the DEM's in Fig. 8" in with_lab
    unused = _report_text(tmp_path, lab=lab, shear=None)
    assert "were given, but no test ran to compare them with" in unused


def test_paper_summary_keeps_lab_only_when_given():
    from poro2d.paper import PaperSummary

    keys = dict(quick=True, seed=0, conversions={}, criterion={}, replicate_specimens=None, shear=None,
                paper={}, timings={}, provenance={})  # fmt: skip
    assert "lab" not in PaperSummary(**keys).to_dict()
    lab = {"source": "a.csv", "kind": "peaks", "peaks": []}
    assert PaperSummary(**keys, lab=lab).to_dict()["lab"] == lab


@dataclass
class _Knob:
    gain: float = 0.5
    steps: int = 10
    mode: str = "a"
    cap: float | None = None

    def __post_init__(self) -> None:
        check_fields(self, _KNOB_RANGES)


_KNOB_RANGES = {
    "gain": Real(0.0, 1.0, lo_open=True),
    "steps": Integer(1, 100),
    "mode": OneOf(("a", "b"), quoted=True),
    "cap": Real(0, None, or_none=True),
}


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"gain": 0.0}, "gain = 0.0 is invalid; allowed: (0.0, 1.0]"),
        ({"gain": "0.3"}, "gain = '0.3' is invalid; allowed: a number"),
        ({"steps": True}, "steps = True is invalid; allowed: an integer in [1, 100]"),
        ({"steps": 4.0}, "steps = 4.0 is invalid; allowed: an integer in [1, 100]"),
        ({"mode": "c"}, "mode = 'c' is invalid; allowed: one of 'a', 'b'"),
        ({"cap": -1}, "cap = -1 is invalid; allowed: [0, inf]"),
        ({"gain": 2.0, "steps": 0}, "gain = 2.0 is invalid"),  # the table's first bad field
    ],
)
def test_a_table_of_ranges_words_its_refusals_as_check_range_does(kw, message):
    with pytest.raises(InputError) as e:
        _Knob(**kw)
    assert str(e.value).startswith(message)
    assert _Knob(cap=None).cap is None  # or_none: None means "not given"


@pytest.mark.parametrize(
    ("cls", "ranges"),
    [(SpecimenSpec, SPECIMEN_RANGES), (CriterionSettings, CRITERION_RANGES), (ShearSettings, SHEAR_RANGES)],
)
def test_every_range_names_a_field_of_its_settings(cls, ranges):
    assert set(ranges) <= {f.name for f in fields(cls)}
    cls()  # the defaults keep every range


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be"])
def test_utf16_named_as_such(tmp_path, encoding):
    """A spreadsheet's "Unicode text" (UTF-16 with its byte order mark) is named, with the fix."""
    f = tmp_path / "lab.csv"
    text = "normal_stress_kpa,shear_stress_kpa\n100,50\n"
    f.write_bytes((b"\xfe\xff" if encoding == "utf-16-be" else b"") + text.encode(encoding))
    with pytest.raises(InputError, match=r"UTF-16 text: save it as UTF-8"):
        read_utf8("--lab", f, "a UTF-8 CSV file")
