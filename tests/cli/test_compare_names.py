"""A cam name with control characters cannot break the compare table into extra lines (issue 12)."""

from __future__ import annotations

from camcad.cli import main
from tests.cli.test_cli import HARMONIC, edit


def test_compare_prints_one_line_per_quantity_whatever_the_names(tmp_path, capsys):
    plain, hostile = tmp_path / "a.toml", tmp_path / "b.toml"
    plain.write_text(HARMONIC)
    hostile.write_text(edit(HARMONIC, r"^name = .*$", 'name = "evil\\\\nM30\\\\n\\\\u001b[2Jname"'))
    assert main(["compare", str(plain), str(plain)]) == 0
    reference = capsys.readouterr().out.splitlines()
    assert main(["compare", str(plain), str(hostile)]) == 0
    lines = capsys.readouterr().out.splitlines()
    # the names may go into a legend (A = …, B = …) to fit 100 columns: one line per name, per quantity
    quantities = [line.split("  ")[0] for line in reference if line[:1].islower() and "=" not in line[:2]]
    for quantity in quantities:
        assert sum(line.startswith(quantity) for line in lines) == 1, quantity
    assert all("\x1b" not in line and len(line) <= 100 for line in lines)
    assert sum("evil M30" in line for line in lines) == 1
