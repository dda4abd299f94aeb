"""Tests of ambseal.report.figures: PNG files are written atomically from plain arrays."""

from __future__ import annotations

import numpy as np
import pytest

from ambseal.errors import AmbsealError
from ambseal.report import figures

PNG = b"\x89PNG\r\n\x1a\n"


def _ok(path):
    data = path.read_bytes()
    assert data.startswith(PNG) and len(data) > 2000
    assert not [p for p in path.parent.iterdir() if p.name.endswith(".tmp")]


def test_all_figures_written(tmp_path):
    """Reference: PNG signature (ISO/IEC 15948 §5.2) on each output, no temporary left over;
    curves shaped like P5 Fig. 11–14 (Hz log axis, µm, ms)."""
    f = np.logspace(0, 3, 200)
    s = 1 + 2 / (1 + ((f - 60) / 10) ** 2)
    cases = [("PID, 0 bar", f, s), ("H∞, 2.04 bar", f, s * 1.3), ("unstable", f, np.full_like(f, np.inf))]
    _ok(figures.sensitivity_figure(tmp_path / "s.png", cases))
    _ok(figures.compliance_figure(tmp_path / "c.png", [("PID", f, 1e-7 * s)]))
    _ok(figures.unbalance_figure(tmp_path / "u.png", [("PID", f, 3 * s)]))
    t = np.linspace(0, 100, 500)
    Y = np.column_stack([np.sin(t / 5) * np.exp(-t / 30) * k for k in (1, 0.5, 0.2, 0.8)])
    names = ["A_zeta", "A_eta", "B_zeta", "B_eta"]
    _ok(figures.impulse_figure(tmp_path / "i.png", [("PID", t, Y)], names, currents=[("PID", t, Y / 10)]))


def test_bad_curves_raise(tmp_path):
    """Reference: interface contract — mismatched arrays or a missing folder raise AmbsealError."""
    with pytest.raises(AmbsealError):
        figures.compliance_figure(tmp_path / "x.png", [("a", [1, 2], [1, 2, 3])])
    with pytest.raises(AmbsealError):
        figures.unbalance_figure(tmp_path / "missing" / "x.png", [])
    with pytest.raises(AmbsealError):
        figures.impulse_figure(tmp_path / "i.png", [("a", [0, 1], np.zeros((2, 3)))], ["A", "B"])


def test_log_minor_grid_drawn_as_one_collection(tmp_path):
    """Reference: the decade grid of log paper — minor lines at m·10ᵏ, m = 2…9, strictly
    inside the axis limits; an axis spanning under a decade keeps matplotlib's minor ticks
    (they carry its only labels)."""
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure
    from matplotlib.ticker import LogLocator, NullLocator

    fig = Figure()
    ax, short = fig.subplots(1, 2)
    ax.loglog([3.0, 4000.0], [1.0, 2.0])
    ax.set_xlim(3.0, 4000.0)
    ax.grid(True, which="both", alpha=0.3)
    short.semilogx([2.0, 7.0], [1.0, 2.0])
    figures.save_figure(fig, tmp_path / "g.png", tight=True)
    _ok(tmp_path / "g.png")
    lines = [c for c in ax.collections if isinstance(c, LineCollection)]
    xs = sorted(seg[0][0] for c in lines for seg in c.get_segments() if seg[0][1] == 0)
    expected = [m * 10.0**k for k in range(0, 4) for m in range(2, 10) if 3 < m * 10.0**k < 4000]
    np.testing.assert_allclose(xs, expected)
    assert isinstance(ax.xaxis.get_minor_locator(), NullLocator)
    assert isinstance(short.xaxis.get_minor_locator(), LogLocator)


def test_user_names_are_drawn_as_written(tmp_path):
    """A name with mathtext in it (``$\\alpha_{1}$ \\frac``) in a title, a legend and an
    annotation is drawn as its characters: each text's width equals that of the same
    string drawn with mathtext off, not with it on; the logarithmic axis's tick labels
    keep their mathtext powers of ten."""
    from matplotlib.figure import Figure
    from matplotlib.text import Text

    from ambseal.report.figures import save_figure

    name = "rig $\\alpha_{1}$ \\frac"
    fig = Figure()
    ax = fig.subplots()
    ax.set_yscale("log")
    ax.plot([1, 2], [1, 100], label=name)
    ax.set_title(name)
    ax.annotate(name, (1.5, 10))
    legend = ax.legend()
    save_figure(fig, tmp_path / "f.png")
    r = fig.canvas.get_renderer()

    def width(t: Text, math: bool | None = None) -> float:
        if math is not None:
            t = Text(0, 0, t.get_text(), parse_math=math, figure=fig,
                     fontproperties=t.get_fontproperties())
        return t.get_window_extent(r).width

    for t in (ax.title, legend.get_texts()[0], ax.texts[0]):
        assert width(t) == pytest.approx(width(t, False))
        assert width(t, True) < 0.9 * width(t, False)
    powers = [t for t in ax.yaxis.get_ticklabels() if "$" in t.get_text()]
    assert powers and all(t.get_parse_math() for t in powers)


def test_the_whirl_waterfall_puts_backward_whirl_below_zero():
    """An orbit that turns forward at 120 Hz (30 µm) for the first half and backward at
    240 Hz (80 µm) for the second, on a static offset: the waterfall's largest amplitude
    in each half at +120 Hz and −240 Hz, of those amplitudes (1 %: both lie on bins of
    the 20 Hz resolution, where the Hann window's coherent gain is taken out exactly),
    the offset taken out."""
    from ambseal.report import whirl_waterfall

    t = np.linspace(0.0, 0.4, 16001)
    first = t < 0.2
    w = np.where(first, 2 * np.pi * 120.0, -2 * np.pi * 240.0)
    a = np.where(first, 30e-6, 80e-6)
    orbit = np.c_[a * np.cos(w * t) + 5e-5, a * np.sin(w * t) - 2e-4]
    times, f, S = whirl_waterfall(t, orbit)
    assert np.all(np.diff(f) > 0) and f[0] < 0 < f[-1]
    assert f[1] - f[0] == pytest.approx(20.0)
    for when, hz, um in ((0.05, 120.0, 30.0), (0.35, -240.0, 80.0)):
        col = S[:, np.argmin(np.abs(times - when))]
        assert f[np.argmax(col)] == pytest.approx(hz)
        assert col.max() == pytest.approx(um, rel=0.01)
        assert col[np.argmin(np.abs(f))] < 0.05 * um


def test_the_api617_unbalance_figure_keeps_every_placement_and_af_readable(tmp_path,
                                                                           monkeypatch):
    """API 617's unbalance figure as a person reads it, measured on the drawn figure: each
    case's legend entry is its whole placement (wrapped, not cut) with the AF and speed of
    each of its criticals (four within 1 600 rpm of each other, as a generated compressor's
    H∞ gave: labels on the curves would overlap); no text is drawn over the curves; each
    legend lies beside its panel, inside the figure, over no panel and no other legend,
    also where a panel has eight cases."""
    from types import SimpleNamespace as NS

    from ambseal.report import signoff_figures

    drawn = []
    save = signoff_figures.save_figure
    monkeypatch.setattr(signoff_figures, "save_figure",
                        lambda fig, path, **kw: (drawn.append(fig), save(fig, path, **kw))[1])
    f = np.linspace(1.0, 230.0, 400)
    placements = ["second mode, at the journals 0.241 m and 1.44 m, 180° apart, W = 557.1 kg "
                  "(every journal)", "20 antinode(s): 0.1 m at 0° (W = 60.28 kg, outboard of "
                  "the support)"] * 4
    crowd = [(7000.0, 3.6, 0.87), (7100.0, 2.7, 0.913), (8300.0, 5.3, 1.14),
             (8600.0, 5.6, 1.1)]
    cases = [NS(speed_hz=f, probe_um=np.column_stack([k * f / 40, k * f / 50]), placement=p,
                criticals=[NS(speed_hz=s / 60.0, amplitude_um=a, af=af) for s, a, af in
                           (crowd if k == 1 else [])])
             for k, p in enumerate(placements, start=1)]

    def result(n):
        return NS(cases=cases[:n], vibration_limit_um=25.4, min_hz=110.0, max_hz=175.0,
                  trip_hz=183.0, controller="hinf", passed=True)

    _ok(signoff_figures.api617_unbalance_figure(tmp_path / "u.png",
                                                [result(2), result(8), result(2)]))
    fig = drawn[0]
    renderer = fig.canvas.get_renderer()
    plots = [ax for ax in fig.axes if ax.axison]
    legends = [ax.get_legend() for ax in fig.axes if not ax.axison]
    assert len(plots) == len(legends) == 3
    boxes = [lg.get_window_extent(renderer) for lg in legends]
    inside = fig.bbox
    for lg, box in zip(legends, boxes):
        texts = [" ".join(t.get_text().split()) for t in lg.get_texts()]
        assert texts[0] == (f"case 1: {placements[0]}; AF 0.87 at 7000 rpm, 0.913 at 7100 "
                            "rpm, 1.14 at 8300 rpm, 1.1 at 8600 rpm")
        assert texts[1] == f"case 2: {placements[1]}"
        assert inside.x0 <= box.x0 and box.x1 <= inside.x1
        assert inside.y0 <= box.y0 and box.y1 <= inside.y1
        assert not any(box.overlaps(ax.get_window_extent(renderer)) for ax in plots)
    assert not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])
    assert not any(ax.texts for ax in plots)


def test_a_discrete_controllers_gains_are_taken_on_the_unit_circle(tmp_path, monkeypatch):
    """Reference: python-control's frequency response of a discrete controller, K(e^{jωT}),
    below the Nyquist frequency only (a design on the sampled plant has no continuous
    form to plot at s = jω); a continuous one beside it at s = jω, up to 2 kHz."""
    import control

    from ambseal.report import run_report

    got = {}
    monkeypatch.setattr(run_report, "controller_gains_figure",
                        lambda path, rows, names, styles: got.update(rows=rows) or path)
    T = 1.0 / 3000.0  # Nyquist at 1.5 kHz, inside the figure's 2 kHz
    Kc = control.ss([[-800.0, 0.0], [0.0, -1200.0]], np.eye(2), [[2e4, 3e3], [1e3, 1.5e4]],
                    np.diag([40.0, 30.0]), inputs=["y_A_zeta", "y_A_eta"],
                    outputs=["i_A_zeta", "i_A_eta"])
    Kd = control.sample_system(Kc, T, method="tustin")
    run_report.gains_figure(tmp_path, [("pid", Kc), ("hinf", Kd)])
    (_, fc, Gc), (_, fd, Gd) = got["rows"]
    assert fc[-1] == pytest.approx(2000.0) and fd.max() < 1500.0 < fd.max() * 1.05
    ref_c = control.frequency_response(Kc, 2 * np.pi * fc)
    ref_d = control.frequency_response(Kd, 2 * np.pi * fd)
    assert np.allclose(np.moveaxis(Gc, 0, -1), ref_c.complex, rtol=1e-9)
    assert np.allclose(np.moveaxis(Gd, 0, -1), ref_d.complex, rtol=1e-9)
