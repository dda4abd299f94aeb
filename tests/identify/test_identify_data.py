"""Tests of ambseal.identify.records.data: the measurement file format (CSV + sidecar, .mat) and its checks."""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.io

from ambseal.errors import DataError
from ambseal.identify.records.data import (
    FORMAT_TAG,
    Measurement,
    column_names,
    load_measurement,
    save_measurement,
    validate_measurement,
)
from ambseal.identify.excitation.signals import DEFAULT_AXES, prbs

FS = 5000.0
N = 600


def _meas(axes=DEFAULT_AXES, n=N, limit=3.0) -> Measurement:
    rng = np.random.default_rng(7)
    k = len(axes)
    ex = prbs(amplitude_a=0.1, clock_period_s=1e-3, duration_s=n / FS, sample_rate_hz=FS, axes=axes, seed=2)
    t = np.arange(n) / FS
    i_ref = ex.values_a + 0.5 * rng.standard_normal((n, k)) / 3
    i_meas = i_ref + 1e-3 * rng.standard_normal((n, k))
    x = 1e-5 * rng.standard_normal((n, k))
    meta = {
        "rig": "thesis test facility",
        "bias_current_a": 6.0,
        "pressure_drop_pa": 0.95e5,
        "speed_rad_s": 0.0,
        "controller": {"name": "PID", "kp_a_per_m": 1.2e4},
        "excitation": ex.params,
        "current_limit_a": limit,
    }
    return Measurement(t, ex.values_a, i_ref, i_meas, x, axes, meta)


def _rewrite_cell(path, row, column, text):
    """Replace one CSV cell (1-based data row, column name) by `text`."""
    lines = path.read_text().splitlines()
    header = lines[0].split(",")
    c = header.index(column)
    fields = lines[row].split(",")
    fields[c] = text
    lines[row] = ",".join(fields)
    path.write_text("\n".join(lines) + "\n")


def _assert_equal(a: Measurement, b: Measurement):
    assert a.axes == b.axes
    for fld in ("time_s", "excitation_a", "current_ref_a", "current_a", "displacement_m"):
        np.testing.assert_array_equal(getattr(a, fld), getattr(b, fld))


# --------------------------------------------------------------------------- round trips
@pytest.mark.parametrize("suffix", [".csv", ".mat"])
def test_round_trip_exact(tmp_path, suffix):
    """Reference: IEEE 754 binary64 — 17 significant digits (CSV) and raw doubles (MAT v5)
    reproduce every value bit for bit; the metadata (incl. Excitation.params) survives as JSON;
    sample_rate_hz is added from the time column."""
    m = _meas()
    p = save_measurement(m, tmp_path / f"run{suffix}")
    back = load_measurement(p, axes=DEFAULT_AXES, min_samples=100)
    _assert_equal(m, back)
    assert back.metadata["excitation"] == json.loads(json.dumps(m.metadata["excitation"]))
    assert back.metadata["controller"] == m.metadata["controller"]
    assert back.metadata["sample_rate_hz"] == pytest.approx(FS, rel=1e-12)
    assert back.sample_rate_hz == pytest.approx(FS, rel=1e-12)
    assert not [q for q in tmp_path.iterdir() if q.name.endswith(".tmp")]
    json.dumps(back.to_dict())


def test_csv_layout_and_sidecar(tmp_path):
    """Reference: the format spec in ambseal.identify.records.data — header `time_s` then per axis
    excitation/current_ref/current/displacement columns; sidecar `<file>.json` with the format
    tag and the axes at top level beside the metadata."""
    m = _meas()
    p = save_measurement(m, tmp_path / "run.csv")
    header = p.read_text().splitlines()[0].split(",")
    assert header == column_names(DEFAULT_AXES)
    assert header[:5] == ["time_s", "excitation_A_zeta_a", "current_ref_A_zeta_a", "current_A_zeta_a",
                          "displacement_A_zeta_m"]
    side = json.loads((tmp_path / "run.csv.json").read_text())
    assert side["format"] == FORMAT_TAG and side["axes"] == list(DEFAULT_AXES)
    assert side["rig"] == "thesis test facility" and side["current_limit_a"] == 3.0


def test_mat_layout_column_vectors(tmp_path):
    """Reference: MATLAB level-5 MAT format via scipy.io — one n×1 double per column plus the
    char variable metadata_json (no objects, nothing to unpickle)."""
    m = _meas()
    p = save_measurement(m, tmp_path / "run.mat")
    raw = scipy.io.loadmat(p)
    for c in column_names(DEFAULT_AXES):
        assert raw[c].shape == (N, 1) and raw[c].dtype == np.float64
    meta = json.loads(str(raw["metadata_json"][0]))
    assert meta["format"] == FORMAT_TAG and meta["axes"] == list(DEFAULT_AXES)


def test_load_reorders_to_rig_axes(tmp_path):
    """Reference: interface contract — columns are matched by name, the result follows the
    rig's axis order."""
    m = _meas()
    p = save_measurement(m, tmp_path / "run.csv")
    order = ("B_eta", "A_zeta", "B_zeta", "A_eta")
    back = load_measurement(p, axes=order)
    assert back.axes == order
    np.testing.assert_array_equal(back.displacement_m[:, 0], m.displacement_m[:, 3])


# --------------------------------------------------------------------------- failures
def _expect(path, match, **kw):
    with pytest.raises(DataError, match=match) as exc:
        load_measurement(path, **kw)
    assert str(path) in str(exc.value) or path.name in str(exc.value)
    return str(exc.value)


def test_nan_names_column_and_row_csv(tmp_path):
    """Reference: format spec — NaN anywhere fails with the column and the 1-based data row."""
    p = save_measurement(_meas(), tmp_path / "run.csv")
    _rewrite_cell(p, 37, "current_B_eta_a", "nan")
    msg = _expect(p, "current_B_eta_a", axes=DEFAULT_AXES)
    assert "row 37" in msg


def test_inf_names_column_and_row_mat(tmp_path):
    """Reference: format spec — ±inf in a .mat column fails with the column and row."""
    m = _meas()
    d = m.displacement_m.copy()
    d[122, 2] = np.inf
    bad = Measurement(m.time_s, m.excitation_a, m.current_ref_a, m.current_a, d, m.axes, m.metadata)
    p = save_measurement(bad, tmp_path / "run.mat")
    msg = _expect(p, "displacement_B_zeta_m")
    assert "row 123" in msg


def test_not_a_number_cell_and_short_row(tmp_path):
    """Reference: format spec — an unparsable cell names column and row; a row with a wrong
    field count names the row."""
    p = save_measurement(_meas(), tmp_path / "run.csv")
    _rewrite_cell(p, 5, "excitation_A_eta_a", "0.1A")
    msg = _expect(p, "excitation_A_eta_a")
    assert "row 5" in msg
    p2 = save_measurement(_meas(), tmp_path / "run2.csv")
    lines = p2.read_text().splitlines()
    lines[9] = ",".join(lines[9].split(",")[:-1])
    p2.write_text("\n".join(lines) + "\n")
    assert "row 9" in _expect(p2, "fields")


def test_non_uniform_and_non_monotone_time(tmp_path):
    """Reference: format spec — each time step within 1e-6 (relative) of the mean step; the
    first offending step is reported at the row where it ends."""
    p = save_measurement(_meas(), tmp_path / "run.csv")
    _rewrite_cell(p, 100, "time_s", repr(99 / FS + 0.3 / FS))
    msg = _expect(p, "time_s")
    assert "row 100" in msg and "not uniform" in msg
    p2 = save_measurement(_meas(), tmp_path / "run2.csv")
    _rewrite_cell(p2, 50, "time_s", repr(47 / FS))
    msg = _expect(p2, "time_s")
    assert "row 50" in msg and "does not increase" in msg
    # jitter below the tolerance is accepted
    p3 = save_measurement(_meas(), tmp_path / "run3.csv")
    _rewrite_cell(p3, 100, "time_s", repr(99 / FS * (1 + 1e-9)))
    load_measurement(p3)


def test_wrong_channel_count_and_other_rig(tmp_path):
    """Reference: format spec — a file for a rig with other axes (count or names) fails on
    the `axes` check of the thesis rig (P2 Fig. 1(b): A_zeta, A_eta, B_zeta, B_eta)."""
    two = save_measurement(_meas(axes=("A_zeta", "A_eta")), tmp_path / "two.csv")
    msg = _expect(two, "axes", axes=DEFAULT_AXES)
    assert "2 axes" in msg and "expects 4" in msg
    other = save_measurement(_meas(axes=("A_x", "A_y", "B_x", "B_y")), tmp_path / "other.mat")
    msg = _expect(other, "axes", axes=DEFAULT_AXES)
    assert "A_x" in msg


def test_missing_and_unexpected_columns(tmp_path):
    """Reference: format spec — every column of the axes must exist and no other."""
    p = save_measurement(_meas(), tmp_path / "run.csv")
    lines = p.read_text().splitlines()
    lines[0] = lines[0].replace("displacement_B_eta_m", "displacement_B_eta_mm")
    p.write_text("\n".join(lines) + "\n")
    _expect(p, "missing column 'displacement_B_eta_m'")
    m = _meas()
    mdict = {c: m.table()[:, i][:, None] for i, c in enumerate(column_names(m.axes))}
    mdict["hall_A_1"] = np.zeros((N, 1))
    mdict["metadata_json"] = json.dumps({"format": FORMAT_TAG, "axes": list(m.axes)})
    scipy.io.savemat(tmp_path / "extra.mat", mdict)
    _expect(tmp_path / "extra.mat", "column 'hall_A_1' is unexpected")


def test_too_few_samples(tmp_path):
    """Reference: format spec — fewer than min_samples samples fails on time_s."""
    p = save_measurement(_meas(), tmp_path / "run.csv")
    msg = _expect(p, "time_s", min_samples=1000)
    assert f"{N} samples" in msg and "1000" in msg


def test_clipped_currents(tmp_path):
    """Reference: format spec — ≥ 3 consecutive samples within 0.1 % of ±limit count as
    clipping (amplifier saturation, P2 §6 notes the linear model fails there); the limit comes
    from the argument or the sidecar; two samples at the limit are accepted."""
    m = _meas(limit=3.0)
    i = m.current_a.copy()
    i[200:203, 1] = -2.998  # within 0.1 % of 3 A
    clipped = Measurement(m.time_s, m.excitation_a, m.current_ref_a, i, m.displacement_m, m.axes, m.metadata)
    p = save_measurement(clipped, tmp_path / "run.csv")
    msg = _expect(p, "current_A_eta_a")
    assert "row 201" in msg and "clipped" in msg
    # an explicit larger limit overrides the sidecar's
    load_measurement(p, current_limit_a=5.0)
    i2 = m.current_a.copy()
    i2[200:202, 1] = 3.0
    two = Measurement(m.time_s, m.excitation_a, m.current_ref_a, i2, m.displacement_m, m.axes, m.metadata)
    load_measurement(save_measurement(two, tmp_path / "two.csv"))
    # reference current clipping is found too
    r = m.current_ref_a.copy()
    r[10:20, 3] = 2.9995
    ref = Measurement(m.time_s, m.excitation_a, r, m.current_a, m.displacement_m, m.axes, {"rig": "x"})
    msg = _expect(save_measurement(ref, tmp_path / "ref.mat"), "current_ref_B_eta_a", current_limit_a=3.0)
    assert "row 11" in msg


def test_missing_sidecar_and_wrong_format(tmp_path):
    """Reference: format spec — the sidecar is required and must carry the format tag."""
    p = save_measurement(_meas(), tmp_path / "run.csv")
    side = tmp_path / "run.csv.json"
    text = side.read_text()
    side.unlink()
    _expect(p, "missing metadata sidecar")
    side.write_text(text.replace(FORMAT_TAG, "ambseal-measurement/0"))
    _expect(p, "format")
    side.write_text("{not json")
    _expect(p, "not valid JSON")
    _expect(tmp_path / "nothing.csv", "not found")
    with pytest.raises(DataError, match="unknown measurement file type"):
        load_measurement(tmp_path / "run.txt")


def test_in_memory_checks_and_constructor(tmp_path):
    """Reference: interface contract — shape errors at construction, value checks through
    validate_measurement with a source name; reserved metadata keys refused."""
    m = _meas()
    with pytest.raises(DataError, match="current_a"):
        Measurement(m.time_s, m.excitation_a, m.current_ref_a, m.current_a[:, :3], m.displacement_m, m.axes)
    with pytest.raises(DataError, match="reserved"):
        Measurement(m.time_s, m.excitation_a, m.current_ref_a, m.current_a, m.displacement_m, m.axes,
                    {"format": "x"})
    assert validate_measurement(m, source="sim", current_limit_a=3.0) is m
    with pytest.raises(DataError, match="^sim: column 'time_s'"):
        validate_measurement(m, source="sim", min_samples=10 * N)
    assert m.channel("current_B_zeta_a") is not None
    with pytest.raises(DataError, match="sample_rate_hz"):
        bad = Measurement(m.time_s, m.excitation_a, m.current_ref_a, m.current_a, m.displacement_m, m.axes,
                          {"sample_rate_hz": 4000.0})
        save_measurement(bad, tmp_path / "never.csv")
    assert not list(tmp_path.iterdir())
