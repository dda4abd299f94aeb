"""The main job with identification (``run --truth``) on rigs of other layouts than the
embedded one: no coupling spring (nothing to identify in stage (b)), and the pump (another
rotor, bearings and seals, its AMBs biased at 5 A). The embedded rig runs in the default
suite (tests/test_pipeline.py); these take a minute or more each."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from ambseal.cli import main
from ambseal.config import default_rig_path, load_rig
from ambseal.identify.procedure import seal_test_pressures

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


@pytest.mark.slow
@pytest.mark.parametrize("layout", ["no_spring", "pump"])
def test_run_with_truth_on_other_layouts(layout, tmp_path, capsys):
    """Exit 0 or 1 (a controller failed, the report written), never a traceback; the
    identification is in metrics.json with every parameter the rig has, no coupling
    where there is none, and the seal tested at pressures derived from the rig."""
    if layout == "no_spring":
        rig, truth = _without_spring(tmp_path)
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
