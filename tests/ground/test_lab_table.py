"""The one reader of laboratory CSV files (poro2d.lab_table) and the sieve curve read by its rules."""

import pytest

from poro2d.errors import InputError
from poro2d.grading import GradingCurve
from poro2d.lab_table import parse_number, read_lab_table


def test_a_table_names_each_cell_by_line_and_column(tmp_path):
    p = tmp_path / "lab.csv"
    p.write_bytes(b"\xef\xbb\xbf# a comment\n A , b \n\n1,2\n3,4\n")
    table = read_lab_table(p)
    assert table.header == ("a", "b") and table.lines == (4, 5)
    assert table.where(1, "b") == f"line 5, column 2 of {p}"
    assert list(table.column("b", 0.0, 10.0)) == [2.0, 4.0]
    with pytest.raises(InputError, match=r"line 5, column 2 .*\[0, 3\] kPa \(why\)"):
        table.column("b", 0.0, 3.0, "kPa", "why")


@pytest.mark.parametrize(
    ("text", "allowed"),
    [("1_000", "digits, sign"), ("nan", "finite"), ("-inf", "finite"), ("1,5", "a number"), ("", "a number")],
)
def test_numbers_are_what_spreadsheets_write(text, allowed):
    with pytest.raises(InputError, match=allowed):
        parse_number(text, "cell")
    assert parse_number(" -1.5e3 ", "cell") == -1500.0


def test_a_stray_quote_does_not_join_the_lines_after_it(tmp_path):
    """csv.reader would read the rest of the file as one quoted cell; each line is its own row."""
    p = tmp_path / "lab.csv"
    p.write_text('a,b\n"1,2\n3,4\n5,6\n')
    with pytest.raises(InputError, match=r"line 2, column 2 .*2 columns, as the header"):
        read_lab_table(p)
    p.write_text('a,b\n1,"2\n3,4\n')
    assert read_lab_table(p).rows == (("1", "2"), ("3", "4"))


def test_a_sieve_curve_with_a_byte_order_mark_is_read(tmp_path):
    p = tmp_path / "g.csv"
    p.write_bytes(b"\xef\xbb\xbfsize_mm,percent_passing\r\n0.2,0\r\n0.4,100\r\n")
    assert GradingCurve.from_csv(p, upscale=10).percent_passing == (0.0, 100.0)


@pytest.mark.parametrize(
    ("body", "words"),
    [("0.2,0\n0.4,1_00\n", ["line 3, column 2", "1_00"]), ("0.2,0\n0.4\n", ["line 3", "percent_passing"])],
)
def test_a_sieve_curve_refuses_cells_naming_line_and_column(tmp_path, body, words):
    p = tmp_path / "g.csv"
    p.write_text("size_mm,percent_passing\n" + body)
    with pytest.raises(InputError) as e:
        GradingCurve.from_csv(p)
    for w in words + ["g.csv"]:
        assert w in str(e.value), (w, str(e.value))
