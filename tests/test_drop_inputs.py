"""Every input of ``ambseal drop`` answered: the ``[[touchdown]]`` tables, the speed, the
seal surge and the Monte-Carlo ranges are refused in one line naming what the user wrote
(exit 2), by the one rule of their rig-file key, or dropped to the right result.

The rig is the rigid rotor of test_cli_drop (two AMBs with a 0.5 mm air gap, rings with a
0.2 mm clearance at both ends of a 100 mm shaft, 20 mm line contacts)."""

from __future__ import annotations

import json
import math

import pytest

from ambseal.analysis.drop_monte_carlo import drop_run
from ambseal.cli import main
from ambseal.config import MAX_SPEED_HZ, load_rig
from ambseal.errors import ConfigError

from .test_cli_drop import _rig_text
from .test_fuzz import _deadline


def _rig(tmp_path, text: str, name: str = "rig.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def _refused(capsys, args, *expect: str) -> str:
    """``main(args)`` (quiet: no progress lines) exits 2 with one line on stderr holding
    each of ``expect``."""
    capsys.readouterr()
    try:
        code = main(["--quiet", *map(str, args)])
    except SystemExit as exc:  # argparse
        code = exc.code
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(lines) == 1, lines
    for part in expect:
        assert part in lines[0], lines[0]
    return lines[0]


def _drop(capsys, rig, *extra) -> dict:
    capsys.readouterr()
    code = main(["--quiet", "drop", str(rig), "--json", "--force", *map(str, extra)])
    out = capsys.readouterr().out
    assert code in (0, 1), out
    return json.loads(out)


def test_duplicate_touchdown_names_are_refused_when_the_rig_is_read(tmp_path, capsys):
    """Two bearings named TA: each bearing's results are keyed by its name (the drop's
    planes, drop_scatter.csv's TA_* columns, the largest peak force over them), so
    ``validate``, a drop and Monte-Carlo drops refuse the rig, naming the key and the
    name."""
    rig = _rig(tmp_path, _rig_text().replace('name = "TB"', 'name = "TA"'))
    for args in (["validate", rig], ["drop", rig, "--out", tmp_path / "d"],
                 ["drop", rig, "--runs", "1", "--out", tmp_path / "d"]):
        _refused(capsys, args, str(rig), "touchdown[1].name", "duplicate touchdown name 'TA'")


def test_a_name_shared_by_a_seal_and_a_touchdown_bearing_is_refused(tmp_path, capsys):
    """A seal named TA beside the touchdown bearing TA: ``--overload-at TA`` would load
    one of the two planes (0.2 m or 0 m) without a word. ``validate``, ``drop``,
    Monte-Carlo drops, ``signoff`` and ``run`` refuse the rig when it is read, naming both
    tables; a seal named "mid" is read."""
    seal = ('[[seal]]\nname = "{}"\nposition = 0.2\nclearance = 3.0e-4\n'
            "k = {{ per_bar = 1.0e6 }}\n")
    rig = _rig(tmp_path, _rig_text() + seal.format("TA"))
    out = ["--out", tmp_path / "d"]
    for args in (["validate", rig], ["drop", rig, *out],
                 ["drop", rig, "--runs", "1", *out],
                 ["drop", rig, "--event", "overload", "--overload-n", "100", "--overload-at",
                  "TA", *out], ["signoff", rig, *out], ["run", rig, *out]):
        _refused(capsys, args, str(rig), "touchdown[0].name: 'TA' is also the name of "
                 "seal[0]")
        assert not (tmp_path / "d").exists()
    assert [s.name for s in load_rig(_rig(tmp_path, _rig_text() + seal.format("mid"),
                                          "ok.toml")).seal] == ["mid"]


def test_a_refused_drop_says_one_line_on_a_pipe(tmp_path, capsys):
    """Without --quiet, stderr a pipe (capsys): a step force of 1e8 N, which crushes the
    ring TA 0.025 ms into the drop, ends a drop and Monte-Carlo drops in exit 2 and the
    one error line, with no progress line or blank line before it; bad options alike.
    The drop's steps stay available with --verbose."""
    rig = _rig(tmp_path, _rig_text())
    crush = ["--event", "overload", "--overload-n", "1e8", "--duration-s", "0.0001",
             "--out", tmp_path / "d"]
    for args, expect in ((["drop", rig, *crush], "pressed 500 µm into the ring of TA"),
                         (["drop", rig, "--runs", "2", *crush], "no drop finished"),
                         (["drop", rig, *crush, "--overload-at", "nowhere"],
                          "--overload-at"),
                         (["drop", rig, "--runs", "2", *crush, "--friction", "3:5"],
                          "--friction 3:5")):
        capsys.readouterr()
        code = main([*map(str, args)])
        lines = capsys.readouterr().err.splitlines()
        assert code == 2 and len(lines) == 1, lines
        assert lines[0].startswith("ambseal: error:") and expect in lines[0], lines
    code = main(["--verbose", *map(str, ["drop", rig, *crush])])
    assert code == 2 and "ms of 0.1 ms" in capsys.readouterr().err


def test_the_monte_carlo_draws_follow_the_rig_files_rules(tmp_path, capsys):
    """A friction drawn in 3:5 lies beyond ``[[touchdown]] friction``'s bound (μ <= 2),
    and a clearance drawn ±150 µm about 0.2 mm reaches a 0.3 mm air gap: each range is
    refused before any run, naming the option and the key whose rule it breaks; a run
    whose draw breaks the rule (one built by hand) is refused by the same rule."""
    rig = _rig(tmp_path, _rig_text())
    _refused(capsys, ["drop", rig, "--runs", "1", "--friction", "3:5", "--out",
                      tmp_path / "d"], "--friction 3:5", "touchdown[0].friction",
             "expected a value <= 2.0, got 3.0")
    assert not (tmp_path / "d").exists()
    tight = _rig(tmp_path, _rig_text().replace("air_gap = 5.0e-4", "air_gap = 3.0e-4"),
                 "tight.toml")
    _refused(capsys, ["drop", tight, "--runs", "1", "--clearance-tol-um", "150", "--out",
                      tmp_path / "d"], "--clearance-tol-um 150",
             "touchdown[0].radial_clearance: 0.00035 m, not below amb[0].air_gap 0.0003 m")
    cfg = load_rig(rig)
    case = {"run": 7, "friction": [0.1, 3.0], "clearance_m": [2e-4, 2e-4],
            "support_damping": [0.0, 0.0], "unbalance_kgm": 0.0}
    with pytest.raises(ConfigError, match=r"drop scatter run 7: touchdown\[1\]\.friction: "
                                          r"expected a value <= 2\.0, got 3\.0"):
        drop_run(case, cfg.model_dump(), 0.0, 0.01, 1e4, False, 0.0)


def _sealed(per_bar: float) -> str:
    """The rig with a seal at mid-span whose cross-coupled stiffness grows ``per_bar``
    (N/m per bar) with the pressure drop, lightly damped."""
    return _rig_text() + ('[[seal]]\nname = "mid"\nposition = 0.2\nclearance = 3.0e-4\n'
                          f"k = {{ per_bar = {per_bar} }}\n"
                          "C = { at_zero = 100.0, per_bar = 50.0 }\n")


def test_a_seal_surge_is_bounded_as_the_pressure_and_ends_where_the_rings_crush(
        tmp_path, capsys):
    """``--surge-bar`` is a pressure drop of the seals: 1e5 bar is refused by the rule of
    ``[operating] pressure_bar`` (<= 1e4), naming ``--surge-bar``, as ``--pressure-bar
    1e5`` is. Within it, a seal surging to 1e4 bar (k = 1e10 N/m) drives a whirl into
    the rings that would crush them: the drop ends in seconds where a ring is pressed 1 %
    of the journal's 50 mm radius deep, under the force of Palmgren's line contact there
    (δ = 3.84e-5 Q^0.9 / l^0.8 in mm and N: Q for δ = 0.5 mm on l = 10 mm); it had
    crawled through the contact for minutes."""
    rig = _rig(tmp_path, _sealed(1.0e6))
    for flag in ("--surge-bar", "--pressure-bar"):
        extra = ["--event", "overload", flag, "1e5"] if flag == "--surge-bar" else [
            flag, "1e5"]
        _refused(capsys, ["drop", rig, "--duration-s", "0.01", "--out", tmp_path / "d",
                          *extra], flag, "expected a value <= 10000.0, got 100000.0",
                 "[operating] pressure_bar")
    force = (0.5 * 10.0 ** 0.8 / 3.84e-5) ** (1 / 0.9)
    with _deadline(60.0):
        _refused(capsys, ["drop", rig, "--event", "overload", "--surge-bar", "1e4",
                          "--duration-s", "0.05", "--out", tmp_path / "d"],
                 "pressed 500 µm into the ring of T", "(1 % of its 50 mm radius)",
                 f"under {force:.3g} N")


def test_a_friction_velocity_below_what_the_drop_resolves_is_refused(tmp_path, capsys):
    """``friction_velocity = 1e-15`` m/s lies below the slip the drop's stiff integrator
    resolves (1e-4 m/s, its rule in the key's description): refused when the rig is read,
    naming the key and the bound; 1e-4 is read."""
    text = _rig_text().replace("friction = 0.1\n", "friction = 0.1\nfriction_velocity = {}\n",
                               1)
    rig = _rig(tmp_path, text.format("1.0e-15"))
    _refused(capsys, ["validate", rig], "touchdown[0].friction_velocity",
             "expected a value >= 0.0001, got 1e-15")
    assert load_rig(_rig(tmp_path, text.format("1.0e-4"), "ok.toml")).touchdown[
        0].friction_velocity == 1e-4


def test_two_rings_at_one_axial_position_are_refused(tmp_path, capsys):
    """Two planes at z = 0 share one node: the drop took one contact onset for both and
    read one plane's first impact as 0 N beside its 931 N peak. Refused when the rig is
    read, naming the second plane's position and the first's name."""
    rig = _rig(tmp_path, _rig_text().replace("position = 0.4\nradial", "position = 0.0\n"
                                                                       "radial"))
    for args in (["validate", rig], ["drop", rig, "--out", tmp_path / "d"]):
        _refused(capsys, args, "touchdown[1].position", "the plane of touchdown[0] ('TA')",
                 "two rings at one axial position")


def test_a_flexible_support_without_its_mass_is_refused_when_the_rig_is_read(tmp_path,
                                                                             capsys):
    """``support_stiffness`` without ``support_mass``: ``validate`` called it valid and
    the drop refused it; now one rule refuses it when the rig is read, for every
    command."""
    rig = _rig(tmp_path, _rig_text().replace("race_inertia = 1.0e-4\n",
                                             "race_inertia = 1.0e-4\nsupport_stiffness = "
                                             "1.0e7\n", 1))
    for args in (["validate", rig], ["drop", rig, "--out", tmp_path / "d"]):
        _refused(capsys, args, "touchdown[0]", "support_stiffness", "give support_mass")


def test_a_rotor_turning_the_other_way_drops_as_the_mirror_image(tmp_path, capsys):
    """``[operating] speed_rpm = -3000`` turns the rotor about −z, as the rig file allows:
    the drop is the mirror image (x → −x) of the drop at +3000 rpm — of a rig symmetric
    under it: the same peak forces, regimes and whirl frequencies, the same coast-down
    time, the rings' and the rotor's final speeds opposite (the mirror's reference is the
    +3000 rpm drop itself). ``--at trip`` keeps the rig's sense (−3150 rpm); before, the
    drop refused the rig naming ``--speed-rpm``, which the user never gave."""
    docs = []
    for rpm in ("3000.0", "-3000.0"):
        rig = _rig(tmp_path, _rig_text().replace("speed_rpm = 3000.0", f"speed_rpm = {rpm}"),
                   f"rig{rpm}.toml")
        docs.append(_drop(capsys, rig, "--duration-s", "0.02", "--coast-down",
                          "--drag-torque", "1", "--out", tmp_path / "d"))
    fwd, rev = docs
    assert rev["speed_rpm"] == -3000.0
    for a, b in zip(fwd["planes"], rev["planes"]):
        assert b["peak_force_n"] == pytest.approx(a["peak_force_n"], rel=1e-4)
        assert b["regime"] == a["regime"]
        assert b["whirl_hz"] == pytest.approx(a["whirl_hz"], rel=1e-4)
        assert b["final_race_speed_rad_s"] == pytest.approx(-a["final_race_speed_rad_s"],
                                                            rel=1e-4)
    assert rev["final_speed_rad_s"] == pytest.approx(-fwd["final_speed_rad_s"], rel=1e-9)
    assert fwd["coast_down_s"] > 0
    assert rev["coast_down_s"] == pytest.approx(fwd["coast_down_s"], rel=1e-4)
    trip = _drop(capsys, tmp_path / "rig-3000.0.toml", "--at", "trip", "--duration-s",
                 "0.002", "--out", tmp_path / "d")
    assert trip["speed_rpm"] == pytest.approx(-3150.0)


def test_the_speed_in_hz_is_bounded_as_the_speed_in_rpm(tmp_path, capsys):
    """``--speed-hz`` is ``[operating] speed_rpm``'s speed in other units: 50 000 Hz
    (3e6 rpm) is refused as ``--speed-rpm 3000000`` is, and 200 000 Hz, each naming the
    option given; −50 Hz turns the rotor the other way at 3000 rpm."""
    rig = _rig(tmp_path, _rig_text())
    out = ["--out", tmp_path / "d", "--duration-s", "0.002"]
    bound = f"expected a value <= {60 * MAX_SPEED_HZ!r}"
    _refused(capsys, ["drop", rig, "--speed-rpm", "3000000", *out], "--speed-rpm", bound,
             "[operating] speed_rpm")
    for hz, rpm in (("50000", "3e+06"), ("200000", "1.2e+07")):
        line = _refused(capsys, ["drop", rig, "--speed-hz", hz, *out],
                        f"--speed-hz {hz} (= {rpm} rpm)", bound, "[operating] speed_rpm")
        assert "--speed-rpm" not in line
    doc = _drop(capsys, rig, "--speed-hz", "-50", *out)
    assert doc["speed_rpm"] == -3000.0
    assert doc["speed_rad_s"] == pytest.approx(-100 * math.pi)


def test_every_speed_has_one_bound_in_rpm_and_hz(tmp_path, capsys):
    """One bound, :data:`~ambseal.config.MAX_SPEED_HZ` (× 60 in rpm), for every speed
    however it is given: 5 % below it a rig's ``speed_rpm``, ``speed_range_hz``,
    ``trip_speed_hz`` and ``[controller.pid] cross_speed_rpm`` are read; 5 % above it
    each rig key, and ``--speed-rpm`` of ``drop`` and ``modes`` and ``--speed-hz`` of ``drop``, ``sweep``
    and ``campbell``, are refused naming the key or option written (exit 2)."""
    below, above = 0.95 * MAX_SPEED_HZ, 1.05 * MAX_SPEED_HZ
    base = _rig_text().replace("speed_rpm = 3000.0\n", "")

    def rig(name, text):
        return _rig(tmp_path, base + text, name)

    pid = "[controller.pid]\nkp = 1.0e4\nti = 0.1\ntd = 1.0e-3\neps = 0.1\ncross_kp = 100.0\n"
    fast = load_rig(rig("fast.toml", f"speed_rpm = {60 * below!r}\nspeed_range_hz = "
                                     f"[1.0, {below!r}]\ntrip_speed_hz = {below!r}\n"
                                     f"{pid}cross_speed_rpm = {60 * below!r}\n"))
    assert fast.operating.trip_hz == fast.operating.continuous_hz[1] == below
    assert fast.controller.pid.cross_speed_rpm == 60 * below
    for k, (key, text) in enumerate((
            ("speed_rpm", f"speed_rpm = {60 * above!r}\n"),
            ("speed_rpm", f"speed_rpm = {-60 * above!r}\n"),
            ("speed_range_hz", f"speed_range_hz = [1.0, {above!r}]\n"),
            ("trip_speed_hz", f"trip_speed_hz = {above!r}\n"),
            ("cross_speed_rpm", f"{pid}cross_speed_rpm = {60 * above!r}\n"))):
        path = rig(f"over{k}.toml", text)
        _refused(capsys, ["validate", path], str(path),
                 "controller.pid" if key == "cross_speed_rpm" else "operating", key)
    ok = rig("ok.toml", "speed_rpm = 3000.0\n")
    out = ["--out", tmp_path / "d"]
    for args, option in ((["drop", ok, "--speed-rpm", 60 * above, *out], "--speed-rpm"),
                         (["modes", ok, "--speed-rpm", 60 * above], "--speed-rpm"),
                         (["drop", ok, "--speed-hz", above, *out], "--speed-hz"),
                         (["sweep", ok, "--speed-hz", f"0:{above!r}:2", *out], "--speed-hz"),
                         (["campbell", ok, "--speed-hz", f"0:{above!r}:2", *out],
                          "--speed-hz")):
        line = _refused(capsys, args, option)
        rpm = 60 * MAX_SPEED_HZ
        assert repr(rpm) in line or f"{rpm:g} rpm" in line, line
        assert not (tmp_path / "d").exists()


def test_the_backup_clearance_lies_inside_the_air_gap_and_the_probe_gap(tmp_path, capsys):
    """A ring 0.6 mm from the journal beside a 0.5 mm air gap lets the rotor hit the
    stator first: refused when the rig is read, naming both keys; a probe gap of 0.15 mm
    inside the rings' 0.2 mm alike; and an AMB's own ``backup_clearance`` on a rig
    without rings. 0.2 mm inside 0.5 mm is read."""
    cases = [(_rig_text().replace("radial_clearance = 2.0e-4", "radial_clearance = 6.0e-4"),
              "touchdown[0].radial_clearance: 0.0006 m, not below amb[0].air_gap 0.0005 m",
              "AMB's stator"),
             (_rig_text().replace("air_gap = 5.0e-4", "air_gap = 5.0e-4\nsensor_gap = 1.5e-4"),
              "touchdown[0].radial_clearance: 0.0002 m, not below amb[0].sensor_gap "
              "0.00015 m", "probe"),
             (_rig_text(touchdown=False).replace("air_gap = 5.0e-4",
                                                 "air_gap = 5.0e-4\nbackup_clearance = "
                                                 "5.0e-4"),
              "amb[0].backup_clearance: 0.0005 m, not below amb[0].air_gap 0.0005 m",
              "AMB's stator")]
    for k, (text, key, what) in enumerate(cases):
        rig = _rig(tmp_path, text, f"rig{k}.toml")
        _refused(capsys, ["validate", rig], str(rig), key, what)
    assert load_rig(_rig(tmp_path, _rig_text(), "ok.toml")).touchdown[0].radial_clearance \
        == 2e-4


def test_a_drop_above_the_trip_speed_is_refused_naming_the_option(tmp_path, capsys):
    """The rig runs at 3000 rpm with no trip speed given: its trip speed is API 617's
    105 % of it, 52.5 Hz (3150 rpm). ``--speed-hz 2000`` and ``--speed-rpm 3200`` are
    refused, each naming the option as given and the trip speed, single or Monte-Carlo;
    with ``trip_speed_hz = 60`` the drop runs at 60 Hz and 61 Hz is refused naming the
    key."""
    rig = _rig(tmp_path, _rig_text())
    out = ["--out", tmp_path / "d", "--duration-s", "0.002"]
    for given, text in ((["--speed-hz", "2000"], "--speed-hz 2000: 2000 Hz"),
                        (["--speed-rpm", "3200"], "--speed-rpm 3200: 53.3333 Hz")):
        for runs in ([], ["--runs", "2"]):
            line = _refused(capsys, ["drop", rig, *given, *runs, *out], text,
                            "trip speed 52.5 Hz = 3150 rpm", "1.05 × the maximum")
            assert "[operating] trip_speed_hz" not in line
    tripped = _rig(tmp_path, _rig_text() + "trip_speed_hz = 60.0\n", "tripped.toml")
    _refused(capsys, ["drop", tripped, "--speed-hz", "-61", *out], "--speed-hz -61",
             "trip speed 60 Hz", "[operating] trip_speed_hz")
    assert _drop(capsys, tripped, "--speed-hz", "60", *out)["speed_rpm"] == 3600.0


def test_the_penetration_ratio_is_set_from_the_command_line_by_its_keys_rule(tmp_path,
                                                                            capsys):
    """``--penetration-ratio`` stands for ``[drop] penetration_ratio``: 0 is refused by
    the key's rule, naming the option; a share below the drop's deepest penetration
    over the clearance makes the verdict fail on the contact law's range (exit 1), one
    above it does not, for the same drop."""
    rig = _rig(tmp_path, _rig_text())
    out = ["--out", tmp_path / "d", "--duration-s", "0.01"]
    _refused(capsys, ["drop", rig, "--penetration-ratio", "0", *out],
             "--penetration-ratio 0", "[drop] penetration_ratio")
    doc = _drop(capsys, rig, *out)
    deep = max(p["max_penetration_m"] for p in doc["planes"]) / 2.0e-4
    assert doc["beyond_range"] == [] and 0 < deep < 0.5
    low = _drop(capsys, rig, "--penetration-ratio", f"{0.9 * deep:.6g}", *out)
    assert not low["passed"] and low["verdict"].startswith(
        "Drop FAILED, beyond the drop model's range")
    assert {r.split("'s ring")[0] for r in low["beyond_range"]} <= {"TA", "TB"}
    high = _drop(capsys, rig, "--penetration-ratio", f"{1.1 * deep:.6g}", *out)
    assert high["beyond_range"] == []
