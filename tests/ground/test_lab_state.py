"""The laboratory state in geotechnical terms (poro2d.lab_state) against hand-computed numbers.

Toyoura-like sand: e_max = 0.977, e_min = 0.597.
  n_max = 0.977 / 1.977 = 0.494183, n_min = 0.597 / 1.597 = 0.373826
  e = 0.7:  n = 0.7 / 1.7 = 0.411765, Dr = (0.977 - 0.7) / 0.38 = 0.728947
  Dr = 0.8: e = 0.977 - 0.8 * 0.38 = 0.673, n = 0.673 / 1.673 = 0.402271
  rho_s = 2650: rho_d = 2650 / 1.7 = 1558.824 at e = 0.7
The paper's sand: n_max = 0.4571, n_min = 0.3253, rho_d = 1740, rho_s = 2650:
  n = 1 - 1740 / 2650 = 0.343396, e = 2650 / 1740 - 1 = 0.522989.
"""

from __future__ import annotations

import json

import pytest

from poro2d import porosity as P
from poro2d.criterion.density import lab_relative_density
from poro2d.errors import InputError
from poro2d.lab_state import (
    SOLID_DENSITY_RANGE,
    TABLE_KEYS,
    LabState,
    lab_extremes,
    lab_state,
    lab_state_from_table,
)

TOYOURA = {"e_max": 0.977, "e_min": 0.597}
N_MAX, N_MIN = 0.977 / 1.977, 0.597 / 1.597


# ------------------------------------------------------------------ extremes
def test_extremes_from_void_ratios():
    n_max, n_min = lab_extremes(**TOYOURA)
    assert n_max == pytest.approx(0.4941831, abs=1e-7)
    assert n_min == pytest.approx(0.3738259, abs=1e-7)


def test_extremes_from_porosities_are_kept():
    assert lab_extremes(n_max=0.4571, n_min=0.3253) == (0.4571, 0.3253)


def test_no_extremes_is_none():
    assert lab_extremes() is None


def test_extremes_round_trip_through_void_ratios():
    n_max, n_min = lab_extremes(**TOYOURA)
    assert lab_extremes(n_max=n_max, n_min=n_min) == (n_max, n_min)
    assert float(P.void_ratio(n_max)) == pytest.approx(0.977, rel=1e-14)
    assert float(P.void_ratio(n_min)) == pytest.approx(0.597, rel=1e-14)


@pytest.mark.parametrize(
    "kw,param,words",
    [
        ({"e_max": 0.977}, "e_min", ["e_max given without e_min"]),
        ({"e_min": 0.597}, "e_max", ["e_min given without e_max"]),
        ({"n_max": 0.45}, "n_min", ["n_max given without n_min"]),
        ({"n_min": 0.35}, "n_max", ["n_min given without n_max"]),
        ({"e_max": 0.977, "e_min": 0.597, "n_min": 0.35}, "n_min", ["not both", "e_max and e_min given"]),
        ({"e_max": 0.977, "n_min": 0.35}, "n_min", ["not both"]),
        ({"e_max": 0.597, "e_min": 0.977}, "e_max", ["greater than e_min = 0.977"]),
        ({"e_max": 0.6, "e_min": 0.6}, "e_max", ["greater than e_min = 0.6"]),
        ({"n_max": 0.3, "n_min": 0.4}, "n_max", ["greater than n_min = 0.4"]),
        ({"e_max": 0.977, "e_min": -0.1}, "e_min", ["[0, 100]"]),
        ({"e_max": -0.5, "e_min": -0.6}, "e_max", ["[0, 100]"]),
        ({"e_max": float("inf"), "e_min": 0.6}, "e_max", ["finite"]),
        ({"e_max": float("nan"), "e_min": 0.6}, "e_max", ["[0, 100]"]),
        ({"e_max": "0.977", "e_min": 0.6}, "e_max", []),
        ({"n_max": 1.0, "n_min": 0.3}, "n_max", ["[0.0, 1.0)"]),
        ({"n_max": 0.45, "n_min": -0.1}, "n_min", []),
        ({"n_max": True, "n_min": 0.3}, "n_max", ["a number"]),
    ],
)
def test_extremes_refused(kw, param, words):
    with pytest.raises(InputError) as info:
        lab_extremes(**kw)
    assert info.value.parameter == param
    text = str(info.value)
    assert text.startswith(f"{param} = ") and "allowed:" in text
    for w in words:
        assert w in text, (w, text)


# ------------------------------------------------------------------ states and round trips
def test_toyoura_void_ratio():
    s = lab_state(e=0.7, **TOYOURA)
    assert s.given == "e" and s.e == 0.7
    assert s.n_lab == pytest.approx(0.41176, abs=1e-5)
    assert s.n_lab == pytest.approx(0.7 / 1.7, rel=1e-15)
    assert s.relative_density == pytest.approx(0.7289, abs=1e-4)
    assert s.relative_density == pytest.approx(0.277 / 0.38, rel=1e-13)
    assert (s.n_max, s.n_min) == lab_extremes(**TOYOURA)


def test_relative_density_is_the_criterion_s():
    """Dr on void ratios, as criterion.density.lab_relative_density (through porosity.relative_density)."""
    for state in (
        lab_state(e=0.7, **TOYOURA),
        lab_state(n=0.3434, n_max=0.4571, n_min=0.3253),
        lab_state(dry_density=1740, solid_density=2650, n_max=0.4571, n_min=0.3253),
    ):
        assert state.relative_density == pytest.approx(
            lab_relative_density(state.n_lab, state.n_max, state.n_min), rel=1e-12, abs=1e-14
        )
    # the paper's sand: D_r = 0.886 (printed 0.89)
    assert lab_state(n=0.3434, n_max=0.4571, n_min=0.3253).relative_density == pytest.approx(
        0.8864513, abs=1e-6
    )


def test_relative_density_gives_the_state():
    s = lab_state(dr=0.8, **TOYOURA)
    assert s.given == "Dr" and s.relative_density == 0.8
    assert s.e == pytest.approx(0.673, rel=1e-14)
    assert s.n_lab == pytest.approx(0.673 / 1.673, rel=1e-14)  # 0.402271
    assert s.n_lab == pytest.approx(0.402271, abs=1e-6)


def test_relative_density_with_porosity_extremes():
    # e_max = 0.4571 / 0.5429 = 0.841960, e_min = 0.3253 / 0.6747 = 0.482140; Dr = 0.5 -> e = 0.662050
    s = lab_state(dr=0.5, n_max=0.4571, n_min=0.3253)
    assert s.e == pytest.approx((0.4571 / 0.5429 + 0.3253 / 0.6747) / 2, rel=1e-14)
    assert s.e == pytest.approx(0.662050, abs=1e-6)
    assert s.n_lab == pytest.approx(s.e / (1 + s.e), rel=1e-15)


def test_relative_density_ends_are_the_extremes():
    loose, dense = lab_state(dr=0.0, **TOYOURA), lab_state(dr=1.0, **TOYOURA)
    assert loose.e == 0.977 and loose.n_lab == pytest.approx(N_MAX, rel=1e-15)
    assert dense.e == pytest.approx(0.597, rel=1e-14) and dense.n_lab == pytest.approx(N_MIN, rel=1e-14)


def test_dry_density_gives_the_state():
    s = lab_state(dry_density=1740, solid_density=2650)
    assert s.given == "dry_density"
    assert s.n_lab == pytest.approx(1 - 1740 / 2650, rel=1e-15)  # 0.343396
    assert s.e == pytest.approx(2650 / 1740 - 1, rel=1e-13)  # 0.522989
    assert s.relative_density is None and s.n_max is None and s.n_min is None


def test_porosity_alone():
    s = lab_state(n=0.3434)
    assert s == LabState(0.3434, float(P.void_ratio(0.3434)), None, None, None, "n")
    assert s.e == pytest.approx(0.3434 / 0.6566, rel=1e-15)  # 0.522997


@pytest.mark.parametrize("dr", [0.0, 0.25, 0.7289473684210527, 1.0])
def test_round_trip_e_n_dr_rho_d(dr):
    """Dr -> e -> n -> rho_d -> back again: every description of one state gives the same state."""
    rho_s = 2650.0
    s = lab_state(dr=dr, **TOYOURA)
    by_e = lab_state(e=s.e, **TOYOURA)
    by_n = lab_state(n=s.n_lab, **TOYOURA)
    by_rho = lab_state(dry_density=rho_s * (1 - s.n_lab), solid_density=rho_s, **TOYOURA)
    by_n_extremes = lab_state(e=s.e, n_max=s.n_max, n_min=s.n_min)
    for other in (by_e, by_n, by_rho, by_n_extremes):
        assert other.n_lab == pytest.approx(s.n_lab, rel=1e-13, abs=1e-15)
        assert other.e == pytest.approx(s.e, rel=1e-13, abs=1e-15)
        assert other.relative_density == pytest.approx(dr, rel=1e-12, abs=1e-12)
        assert (other.n_max, other.n_min) == (s.n_max, s.n_min)
    assert [o.given for o in (by_e, by_n, by_rho)] == ["e", "n", "dry_density"]


def test_toyoura_dry_density():
    s = lab_state(dry_density=2650 / 1.7, solid_density=2650, **TOYOURA)  # 1558.824 kg/m3
    assert s.e == pytest.approx(0.7, rel=1e-13)
    assert s.relative_density == pytest.approx(0.7289474, abs=1e-7)


def test_to_dict_is_json_ready():
    s = lab_state(e=0.7, **TOYOURA)
    d = s.to_dict()
    assert set(d) == {"n_lab", "e", "n_max", "n_min", "relative_density", "given"}
    assert json.loads(json.dumps(d, allow_nan=False)) == d
    assert LabState(**d) == s
    assert lab_state(n=0.3).to_dict()["relative_density"] is None


def test_state_is_frozen():
    s = lab_state(e=0.7)
    with pytest.raises(AttributeError):
        s.e = 0.8  # type: ignore[misc]


# ------------------------------------------------------------------ refusals
@pytest.mark.parametrize(
    "kw,param,words",
    [
        ({}, "state", ["exactly one of e, n, dr", "no state given"]),
        ({"e_max": 0.977, "e_min": 0.597}, "state", ["no state given"]),
        ({"e": 0.7, "n": 0.4}, "n", ["e = 0.7 given as well"]),
        ({"e": 0.7, "dr": 0.5, **TOYOURA}, "dr", ["e = 0.7 given as well"]),
        ({"n": 0.4, "dry_density": 1600, "solid_density": 2650}, "dry_density", ["n = 0.4 given as well"]),
        ({"e": 0.7, "solid_density": 2650}, "solid_density", ["only together with dry_density"]),
        ({"dry_density": 1600}, "solid_density", ["together with dry_density", "[500, 23000]"]),
        ({"dry_density": 1600, "solid_density": 1e300}, "solid_density", ["[500.0, 23000.0]"]),
        ({"dry_density": 1600, "solid_density": 100}, "solid_density", ["[500.0, 23000.0]"]),
        ({"dry_density": 2700, "solid_density": 2650}, "dry_density", ["at most the solid density"]),
        ({"dry_density": 0, "solid_density": 2650}, "dry_density", ["positive"]),
        ({"dry_density": -1600, "solid_density": 2650}, "dry_density", []),
        ({"dry_density": "1600", "solid_density": 2650}, "dry_density", []),
        ({"dr": 0.5}, "dr", ["e_max and e_min", "n_max and n_min"]),
        ({"dr": 1.2, **TOYOURA}, "dr", ["[0, 1]"]),
        ({"dr": -0.1, **TOYOURA}, "dr", ["[0, 1]"]),
        ({"dr": float("nan"), **TOYOURA}, "dr", ["[0, 1]"]),
        ({"dr": "0.5", **TOYOURA}, "dr", ["[0, 1]"]),
        ({"e": -0.1}, "e", ["[0, 100]"]),
        ({"e": float("inf")}, "e", ["finite"]),
        ({"e": float("nan")}, "e", []),
        ({"e": "0.7"}, "e", []),
        ({"e": None, "n": 1.0}, "n", ["[0.0, 1.0)"]),
        ({"n": -0.2}, "n", []),
        ({"n": True}, "n", ["a number"]),
        ({"e": 0.7, "e_max": 0.977}, "e_min", ["without e_min"]),
        ({"e": 0.7, "e_max": 0.977, "e_min": 0.597, "n_max": 0.5}, "n_max", ["not both"]),
        ({"e": 0.7, "e_max": 0.5, "e_min": 0.6}, "e_max", ["greater than e_min"]),
    ],
)
def test_state_refused(kw, param, words):
    with pytest.raises(InputError) as info:
        lab_state(**kw)
    assert info.value.parameter == param
    text = str(info.value)
    assert text.startswith(f"{param} = ") and "allowed:" in text
    for w in words:
        assert w in text, (w, text)


@pytest.mark.parametrize(
    "kw,param,value,words",
    [
        ({"e": 0.99, **TOYOURA}, "e", 0.99, ["[0.597, 0.977]", "Dr = -0.03421"]),
        ({"e": 0.5, **TOYOURA}, "e", 0.5, ["[0.597, 0.977]", "Dr = 1.255"]),
        ({"n": 0.3, **TOYOURA}, "n", 0.3, ["[0.373826, 0.494183]", "e_min = 0.597, e_max = 0.977"]),
        ({"n": 0.46, "n_max": 0.4571, "n_min": 0.3253}, "n", 0.46, ["[0.3253, 0.4571]"]),
        ({"e": 0.45, "n_max": 0.4571, "n_min": 0.3253}, "e", 0.45, ["n_min = 0.3253, n_max = 0.4571"]),
        # rho_s (1 - n_max) = 2650 / 1.977 = 1340.41, rho_s (1 - n_min) = 2650 / 1.597 = 1659.36
        (
            {"dry_density": 1700, "solid_density": 2650, **TOYOURA},
            "dry_density",
            1700,
            ["[1340.41, 1659.36] kg/m3"],
        ),
    ],
)
def test_state_outside_its_extremes_refused(kw, param, value, words):
    with pytest.raises(InputError) as info:
        lab_state(**kw)
    err = info.value
    assert (err.parameter, err.value) == (param, value)
    assert "between the laboratory extremes" in err.allowed
    for w in words:
        assert w in str(err), (w, str(err))


def test_state_at_its_extremes_accepted():
    assert lab_state(e=0.977, **TOYOURA).relative_density == 0.0
    assert lab_state(e=0.597, **TOYOURA).relative_density == 1.0
    assert lab_state(n=0.4571, n_max=0.4571, n_min=0.3253).relative_density == pytest.approx(0.0, abs=1e-15)
    # n from e against porosity extremes: a rounding error at the edge is inside
    assert lab_state(
        e=float(P.void_ratio(0.3253)), n_max=0.4571, n_min=0.3253
    ).relative_density == pytest.approx(1.0, abs=1e-12)


# ------------------------------------------------------------------ [lab] tables
def test_table_gives_the_same_state():
    table = {"name": "Toyoura sand", "source": "JIS A 1224", "e": 0.7, **TOYOURA}
    assert lab_state_from_table(table) == lab_state(e=0.7, **TOYOURA)
    assert lab_state_from_table({"dr": 0.8, "n_max": 0.4571, "n_min": 0.3253}).given == "Dr"
    assert lab_state_from_table({"dry_density": 1740, "solid_density": 2650}).n_lab == pytest.approx(
        0.3433962, abs=1e-7
    )


def test_table_keys_are_the_keywords():
    assert set(TABLE_KEYS) == {
        "e", "n", "dr", "dry_density", "solid_density", "e_max", "e_min", "n_max", "n_min", "name", "source",
    }  # fmt: skip


def test_table_from_toml():
    import tomllib

    doc = tomllib.loads('[lab]\nname = "Toyoura"\ne_max = 0.977\ne_min = 0.597\ndr = 0.8\n')
    assert lab_state_from_table(doc["lab"]).e == pytest.approx(0.673, rel=1e-14)


@pytest.mark.parametrize(
    "table,param,words",
    [
        ({"e": 0.7, "void_ratio": 0.7}, "lab.void_ratio", ["known keys:", "dry_density", "e_max", "source"]),
        ({"e": 0.7, "Dr": 0.5}, "lab.Dr", ["known keys:"]),
        ({"e": 0.7, "name": 3}, "lab.name", ["a string"]),
        ({"e": 0.7, "source": ["a"]}, "lab.source", ["a string"]),
        ({"e": "0.7"}, "lab.e", ["a finite void ratio"]),
        ({"e": True}, "lab.e", []),
        ({"name": "Toyoura"}, "lab", ["no state given"]),
        ({"e": 0.7, "n": 0.4}, "lab.n", ["e = 0.7 given as well"]),
        ({"e": 1.2, **TOYOURA}, "lab.e", ["[0.597, 0.977]"]),
        ({"dr": 0.8, "e_max": 0.977}, "lab.e_min", ["without e_min"]),
        ({"dr": 0.8}, "lab.dr", ["e_max and e_min"]),
        ({"dry_density": 1700}, "lab.solid_density", ["together with dry_density"]),
    ],
)
def test_table_refused(table, param, words):
    with pytest.raises(InputError) as info:
        lab_state_from_table(table)
    assert info.value.parameter == param
    for w in words:
        assert w in str(info.value), (w, str(info.value))


@pytest.mark.parametrize("table", [[("e", 0.7)], "e = 0.7", None, 0.7])
def test_table_must_be_a_table(table):
    with pytest.raises(InputError) as info:
        lab_state_from_table(table)
    assert info.value.parameter == "lab"


def test_solid_density_range_is_the_command_s(capsys):
    from poro2d.cli import main

    with pytest.raises(SystemExit):  # the command refuses through lab_state, with its range
        main(["convert", "--dry-density", "1600", "--solid-density", "100"])
    assert "[{}, {}]".format(*SOLID_DENSITY_RANGE) in capsys.readouterr().err
