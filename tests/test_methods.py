"""The table of controller methods (:mod:`ambseal.config.methods`) walked through every
layer that reads it: the CLI's choices, the design recipes, the main job's designs,
judgement, exported files and report, and the figures' colours."""

from __future__ import annotations

import html
import json

import pytest

from ambseal.cli import main
from ambseal.config import METHODS, method, method_label, method_names
from ambseal.design.recipes import design
from ambseal.errors import ConfigError
from ambseal.report.figures import controller_colours


def test_the_table_names_each_method_once_with_its_own_colour():
    names = [m.name for m in METHODS]
    assert len(set(names)) == len(names)
    colours = [m.colour for m in METHODS if m.colour is not None]
    assert len(set(colours)) == len(colours)
    assert set(method_names(synthesised=True)) <= set(method_names(fixed=True))
    assert method_names(fixed=True) == ("pid", "hinf", "mu")
    assert method_names(synthesised=True) == ("hinf", "mu")


def test_a_name_no_method_has_is_refused_with_the_known_names():
    with pytest.raises(ConfigError, match="'hinff'.*pid, hinf, mu, lpv, tracked"):
        method("hinff")
    assert method("mu").label == "μ"
    assert method_label("my_controller.json") == "my_controller.json"


@pytest.mark.parametrize("command", ["design", "export"])
def test_the_cli_offers_the_option_methods_and_no_other(command, capsys):
    with pytest.raises(SystemExit) as exc:
        main([command, "--help"])
    assert exc.value.code == 0
    text = capsys.readouterr().out
    assert "{" + ",".join(method_names(option=True)) + "}" in text
    with pytest.raises(SystemExit) as exc:
        main([command, "rig.toml", "--method", "tracked"])
    assert exc.value.code == 2
    assert "invalid choice: 'tracked'" in capsys.readouterr().err


def test_the_recipes_design_the_fixed_methods_and_refuse_the_others(testrig_cfg):
    for name in method_names(fixed=False):
        with pytest.raises(ConfigError, match=f"method='{name}'"):
            design(testrig_cfg, name)


@pytest.mark.xdist_group("terminal_run")
def test_the_main_job_designs_judges_exports_and_reports_every_fixed_method(terminal_run):
    out, m, _ = terminal_run
    fixed = method_names(fixed=True)
    assert [c for c in m["controllers"] if c in fixed] == list(fixed)
    judged = {c["controller"] for c in m["cases"]}
    assert set(fixed) <= judged
    files = {p.name for p in (out / "controllers").iterdir()}
    for name in method_names(synthesised=True):  # the PID is the rig's own
        assert {f"controller_{name}.json", f"ambseal_{name}.c"} <= files
        assert json.loads((out / "controllers" / f"controller_{name}.json").read_text())
    page = html.unescape((out / "report.html").read_text(encoding="utf-8"))
    for name in fixed:
        assert method_label(name) in page
    assert controller_colours(fixed) == {n: method(n).colour for n in fixed}
