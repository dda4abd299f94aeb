"""The main job with identification (``run --truth``) on rigs of other layouts than the
embedded one: no coupling spring (nothing to identify in stage (b)), the pump (another
rotor, bearings and seals, its AMBs biased at 5 A) and three AMBs (a statically
indeterminate rotor: the static loads must be applied at two places). The embedded rig runs in the default
suite (tests/test_pipeline.py); these take a minute or more each."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from ambseal.cli import main
from ambseal.config import default_rig_path, load_rig
from ambseal.identify.fitting.procedure import seal_test_pressures

from .metrics_schema import validate_metrics

ROOT = Path(__file__).resolve().parents[1]
TRUTH = ROOT / "src" / "ambseal" / "data" / "testrig_truth.toml"


def _without_spring(tmp_path: Path) -> tuple[Path, Path]:
    text = default_rig_path().read_text()
    rig_text = re.sub(r"\n\[\[spring\]\]\n(?:[^\n\[#][^\n]*\n)*", "\n", text)
    assert rig_text != text
    truth = "\n".join(ln for ln in TRUTH.read_text().splitlines()
                      if not ln.startswith('"coupling.'))
    (tmp_path / "rig.toml").write_text(rig_text)
    (tmp_path / "truth.toml").write_text(truth + "\n")
    return tmp_path / "rig.toml", tmp_path / "truth.toml"


def _three_ambs(tmp_path: Path) -> tuple[Path, Path]:
    """The embedded rig with a third AMB, C, between A and B, and its truth a few per cent
    off the rig file's factors (as A's and B's are)."""
    amb_c = ('[[amb]]\nname = "C"\nposition = 0.43\nsensor_position = 0.47\n'
             'axes_angle_deg = 45.0\nki = { zeta = 230.0, eta = 235.0 }\n'
             'ks = { zeta = 2.8e6, eta = 2.8e6 }\nbias_current = 6.0\ncurrent_limit = 6.0\n\n')
    text = default_rig_path().read_text()
    rig_text = text.replace("[actuator]", amb_c + "[actuator]", 1)
    truth = TRUTH.read_text().replace(
        '"coupling.kxx"', '"C.Ki_zeta" = 236.0\n"C.Ki_eta" = 229.0\n"C.Ks_zeta" = 2.88e6\n'
        '"C.Ks_eta" = 2.74e6\n"coupling.kxx"', 1)
    (tmp_path / "rig.toml").write_text(rig_text)
    (tmp_path / "truth.toml").write_text(truth)
    return tmp_path / "rig.toml", tmp_path / "truth.toml"


@pytest.mark.slow
@pytest.mark.parametrize("layout", ["no_spring", "pump", "three_ambs"])
def test_run_with_truth_on_other_layouts(layout, tmp_path, capsys):
    """Exit 0 or 1 (a controller failed, the report written), never a traceback; the
    identification is in metrics.json with every parameter the rig has, no coupling
    where there is none, and the seal tested at pressures derived from the rig."""
    if layout == "no_spring":
        rig, truth = _without_spring(tmp_path)
    elif layout == "three_ambs":
        rig, truth = _three_ambs(tmp_path)
    else:
        rig, truth = ROOT / "examples" / "pump.toml", ROOT / "tests" / "data" / "pump_truth.toml"
    out = tmp_path / "out"
    code = main(["--quiet", "run", str(rig), "--truth", str(truth), "--out", str(out)])
    err = capsys.readouterr().err
    assert code in (0, 1) and "Traceback" not in err, err
    m = json.loads((out / "metrics.json").read_text())
    validate_metrics(m)
    ident = m["identification"]
    names = " ".join(ident["parameters"]) if isinstance(ident["parameters"], dict) else \
        json.dumps(ident["parameters"])
    assert ("coupling" in names) == (layout != "no_spring")
    assert (out / "report.html").exists() and (out / "identified_rig.toml").exists()
    ij = json.loads((out / "identification.json").read_text())
    tried = [r["pressure_bar"] for r in ij["seal_vs_pressure"]] + [
        r["pressure_bar"] for r in ij.get("seal_pressures_skipped", [])]
    assert sorted(tried) == pytest.approx(seal_test_pressures(load_rig(rig)))
    assert (ij["coupling"] is None) == (layout == "no_spring")
    if layout == "three_ambs":  # the third AMB's factors found (static loads at two places)
        for axis in ("zeta", "eta"):
            assert abs(ident["parameters"][f"C.Ki_{axis}"]["error_pct"]) < 2.0
