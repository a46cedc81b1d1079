"""The shear velocity's floor: a test too slow to end is refused before any work, and the rate
check's rerun at half the velocity neither trips the floor unasked nor runs below it."""

import pytest

from poro2d.cli.app import main
from poro2d.errors import InputError
from poro2d.shear.run import ShearSeriesCase, run_shear
from poro2d.shear.series import ShearSeries
from poro2d.shear.settings import MIN_VELOCITY, ShearSettings, half_velocity
from poro2d.store import Store


def refusal(args, capsys) -> str:
    """The one line a refused ``poro2d`` command prints (exit 2)."""
    with pytest.raises(SystemExit) as exc:
        main(args)
    printed = capsys.readouterr()
    line = (printed.out + printed.err).strip()
    assert exc.value.code == 2 and len(line.splitlines()) == 1, line
    assert "Traceback" not in line
    return line


@pytest.mark.parametrize("velocity", ["1e-300", "5e-05", "0", "-1", "nan", "inf", "11"])
def test_a_velocity_out_of_range_is_refused_naming_the_option(velocity, specimen, tmp_path, capsys):
    out = tmp_path / "s"
    line = refusal(["shear", "--specimen", str(specimen), "--velocity", velocity, "--out", str(out)], capsys)
    assert line.startswith("error: --velocity = ") and "[0.0001, 10.0]" in line, line
    assert not out.exists()


def test_a_velocity_below_the_floor_in_a_config_is_named_as_its_key(specimen, tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text("[shear]\nvelocity = 1e-9\n")
    out = tmp_path / "s"
    line = refusal(["shear", "--specimen", str(specimen), "--config", str(cfg), "--out", str(out)], capsys)
    assert line.startswith("error: shear.velocity = 1e-09"), line
    assert not out.exists()


def test_the_rate_check_below_the_floor_is_refused_before_the_folder_is_claimed(specimen, tmp_path, capsys):
    """1.5e-4 m/s alone is allowed; its rerun at 7.5e-5 m/s is not: one line naming --velocity,
    the range that holds with the rate check and why."""
    out = tmp_path / "s"
    args = ["shear", "--specimen", str(specimen), "--velocity", "1.5e-4", "--rate-check", "--out", str(out)]
    line = refusal(args, capsys)
    assert line.startswith("error: --velocity = 0.00015"), line
    assert "[0.0002, 10] m/s with the rate check" in line and "half the velocity" in line, line
    assert not out.exists()
    with pytest.raises(InputError, match="velocity"):
        slow = ShearSettings(velocity=1.5e-4)
        run_shear(ShearSeriesCase(specimen, [50], slow, rate_check=True), Store(out))
    assert not out.exists()


def test_a_velocity_at_the_floor_runs_without_the_rate_check(specimen):
    """The half is made only for the rate check: at the floor a series has its one test, and at
    twice the floor the rerun runs exactly at the floor."""
    alone = ShearSeries(specimen, [50], ShearSettings(velocity=MIN_VELOCITY))
    assert [job.case.settings.velocity for job in alone.jobs] == [MIN_VELOCITY]
    checked = ShearSeries(specimen, [50], ShearSettings(velocity=2 * MIN_VELOCITY), rate_check=True)
    assert sorted(job.case.settings.velocity for job in checked.jobs) == [MIN_VELOCITY, 2 * MIN_VELOCITY]
    assert half_velocity(0.025) == 0.0125
    with pytest.raises(InputError, match="below the floor"):
        half_velocity(1.9e-4)
