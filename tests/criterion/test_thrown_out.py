"""A disk thrown out of the box during a run is a physical event of the trial, never an input error."""

from pathlib import Path

import pytest

from poro2d.cli import main
from poro2d.criterion.protocol import thrown_out_note
from poro2d.dem.layout import MisplacedDisk
from poro2d.errors import InputError

#: a well-graded sandy gravel (0.1-18.9 mm, Cu 18): its frictionless jamming porosity is about 0.105
GRAVEL = Path(__file__).parents[2] / "examples" / "soils" / "g1-1_sandy_gravel.csv"


@pytest.mark.slow
def test_a_trial_denser_than_its_grading_jams_is_refused_naming_the_cause(tmp_path, capsys, monkeypatch):
    # 0.06 is within the margin the check before the run lets pass (n_J - 0.05), but in this
    # box a layer's overlaps explode and throw a disk out: before, "disk 74 position is invalid"
    # (with the true masses, the fines' friction in growth and the spec's 40 growth increments it
    # was found with: with the fines' masses raised, docs/density-scaling.md, the fines and walls
    # sliding while the layers grow, docs/criterion.md, or increments finer than the finest disk,
    # compaction.GROWTH_SHARE_OF_FINEST, this trial ends otherwise: an over-full box)
    monkeypatch.setattr("poro2d.specimen.compaction.GROWTH_SHARE_OF_FINEST", 1e9)
    cfg = tmp_path / "gravel.toml"
    cfg.write_text(
        '[specimen]\nwidth = 0.08\nheight = 0.04\nlayers = 2\nmass_scaling = "off"\n'
        'frictionless_fines = "off"\n'
        f'[grading]\ncsv = "{GRAVEL.as_posix()}"\n[criterion]\ntrial_porosity = 0.06\nmax_iterations = 1\n'
    )
    with pytest.raises(SystemExit) as e:
        main(["criterion", "--config", str(cfg), "--out", str(tmp_path / "out"), "--quiet"])
    assert e.value.code == 1  # a refused trial, not a refusal of the input (2)
    out = capsys.readouterr()
    assert "is invalid" not in out.out + out.err
    line = next(x for x in out.out.splitlines() if x.startswith("criterion failed:"))
    assert "trial 1 (n2D = 0.0600) refused: disk" in line and "thrown out of place" in line
    assert "jamming porosity n_J = 0." in line and "trial_porosity (--trial-porosity) at 0." in line


def test_only_a_disk_position_is_taken_for_a_thrown_out_disk():
    moved = MisplacedDisk("disk 850 position", (0.304224, 1.08571), "a centre inside the walls", "beyond")
    assert isinstance(moved, InputError)  # built by hand, a misplaced disk is still bad input
    assert not isinstance(InputError("trial porosity", 0.05, ">= 0.101"), MisplacedDisk)
    note = thrown_out_note(moved, 0.08, 0.1049)
    assert note.startswith("disk 850 was thrown out of place") and "(0.304224, 1.08571) m" in note
    assert "n_J = 0.105" in note and "at 0.11 or above" in note
    assert "what this grading jams at" in thrown_out_note(moved, 0.08, None)


def test_a_disk_thrown_out_at_a_trial_looser_than_jamming_is_not_blamed_on_density():
    """G1-1's frictional calibration cases: "trial n2D = 0.1550 being below this grading's
    jamming porosity n_J = 0.100" (false) and "start looser" (no help) before."""
    moved = MisplacedDisk("disk 1432 position", (0.0909778, -1.27286), "a centre inside the walls", "beyond")
    note = thrown_out_note(moved, 0.155, 0.100)
    assert "being below" not in note and "start looser" not in note
    assert "is looser than this grading's jamming porosity n_J = 0.100" in note
    assert "growth_friction = 0" in note and 'frictionless_fines = "on"' in note
