"""Make the manual's figures with the tool itself (run by hand when the figures change;
the PNGs are committed so that the manual builds in seconds).

    PYTHONPATH=src python docs/figures/make.py [--keep DIR]

Runs ``ambseal run`` on the embedded rig, ``ambseal campbell`` and ``ambseal modes
--shapes`` on the manual's compressor (docs/rigs/compressor.toml) and ``ambseal sweep`` on
examples/testrig.toml, photographs the report in headless Chromium (Debian's
``chromium``), and writes each figure here scaled to 900 px wide with a 256-colour
palette (a few tens of kB each). About 3 minutes on 2 cores.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
RIG = ROOT / "docs" / "rigs" / "compressor.toml"
WIDTH = 900


def ambseal(*args: str, cwd: Path) -> None:
    subprocess.run([sys.executable, "-m", "ambseal.cli", "-q", *args], cwd=cwd, check=True,
                   stdout=subprocess.DEVNULL)


def save(src: Path, name: str, crop_height: int | None = None) -> None:
    im = Image.open(src).convert("RGB")
    if crop_height is not None:
        im = im.crop((0, 0, im.width, min(crop_height, im.height)))
    if im.width > WIDTH:
        im = im.resize((WIDTH, round(im.height * WIDTH / im.width)), Image.LANCZOS)
    im.quantize(colors=256, method=Image.Quantize.MEDIANCUT).save(HERE / name, optimize=True)
    print(f"{name}: {(HERE / name).stat().st_size / 1024:.0f} kB")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--keep", type=Path, help="work in this folder and keep it")
    args = ap.parse_args()
    work = args.keep or Path(tempfile.mkdtemp(prefix="ambseal-figures-"))
    work.mkdir(parents=True, exist_ok=True)

    ambseal("run", "--out", "run", cwd=work)
    for name in ("sensitivity", "compliance", "unbalance", "impulse", "facility_impulse",
                 "ident_seal_pressure", "ident_correlation"):
        save(work / "run" / f"{name}.png", f"{name}.png")
    chromium = shutil.which("chromium")
    if chromium:
        subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu",
                        "--hide-scrollbars", f"--screenshot={work / 'report.png'}",
                        "--window-size=1280,760", (work / "run" / "report.html").as_uri()],
                       check=True, capture_output=True, timeout=120)
        save(work / "report.png", "report.png")

    ambseal("campbell", str(RIG), "--controller", "pid", "--out", "campbell", cwd=work)
    save(work / "campbell" / "campbell_pid.png", "campbell.png")
    ambseal("modes", str(RIG), "--free", "--speed-rpm", "0", "--shapes", "shapes.png",
            cwd=work)
    save(work / "shapes.png", "mode_shapes.png")
    ambseal("sweep", str(ROOT / "examples" / "testrig.toml"), "--pressure-bar", "0:6:13",
            "--controller", "pid,hinf,mu", "--out", "sweep", cwd=work)
    save(work / "sweep" / "stability_map.png", "stability_map.png")
    if not args.keep:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
