"""ambseal in one page: rig → model → design → judge → export (``python examples/tutorial.py``).

Writes σ̄(S_o) with the ISO 14839-3 zones and the H∞ controller to ``OUT`` (default tutorial-out).
"""
import sys
from pathlib import Path

import control

from ambseal.analysis.judge import judge, judge_settings, operating_points
from ambseal.app.commands import digital_for
from ambseal.config import load_rig
from ambseal.export.controller_files import export_controller
from ambseal.design import design, design_spec
from ambseal.model.rig import build_plant
from ambseal.report.figures import sensitivity_figure

out = Path(sys.argv[1] if len(sys.argv) > 1 else "tutorial-out")
out.mkdir(parents=True, exist_ok=True)
rig = load_rig(Path(__file__).with_name("testrig.toml"))        # 1. the rig file (TOML)
model = build_plant(rig, reduced=True)                          # 2. the reduced model
print(f"model: {model.n_states} states, axes {', '.join(model.axes)}")
hinf = design(rig, "hinf", spec=(spec := design_spec(rig)))    # 3. H∞ design (thesis P5 §4)
points, settings, curves = operating_points(spec), judge_settings(spec), []
for point in points:                                            # 4. judged on the full model
    case, c = judge(rig, hinf.K, "hinf", point, settings)
    print(f"{point.label}: stable={case.stable}, ISO zone per axis "
          f"{case.iso_zone_per_axis}, orbit {case.unbalance_peak_um:.3g} µm")
    curves.append((point.label, *c["So"]))
sensitivity_figure(out / "sensitivity.png", curves)
dc = digital_for(rig, "hinf", hinf.K, hinf, points)  # 5. discretised, checked on the sampled plant
export_controller(dc, out / "K_hinf.npz")                       # 6. for the target
# The same loop in python-control, wired by signal names (i = −K y):
G = control.ss(build_plant(rig).to_statespace(), name="G")
K = control.ss(hinf.K, name="K")
loop = control.interconnect([G, K], outlist=list(G.output_labels),
                            connections=[[f"G.i_{a}", f"-K.i_{a}"] for a in model.axes]
                            + [[f"K.y_{a}", f"G.y_{a}"] for a in model.axes])
print(f"closed loop at nominal pressure: largest real pole {max(loop.poles().real):.1f} rad/s")
