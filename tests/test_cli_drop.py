"""``ambseal drop``: the rotor released onto its touchdown bearings from the command line,
its JSON and figure; a rig it cannot drop refused in one line (exit 2)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from ambseal.cli import main
from ambseal.config import load_rig

from .rigid_rotor import L, rotor_text


def _rig_text(touchdown: bool = True) -> str:
    text = rotor_text("rigid rotor on touchdown bearings", 20.0, 0.05, 0.1, 4)
    for name, z in (("A", 0.1), ("B", L - 0.1)):
        text += (f'[[amb]]\nname = "{name}"\nposition = {z}\nsensor_position = {z}\n'
                 "ki = 100.0\nks = 2.0e5\nbias_current = 5.0\ncurrent_limit = 10.0\n"
                 "air_gap = 5.0e-4\n")
    if touchdown:
        for name, z in (("TA", 0.0), ("TB", L)):
            text += (f'[[touchdown]]\nname = "{name}"\nposition = {z}\n'
                     "radial_clearance = 2.0e-4\ncontact_length = 0.01\n"
                     "restitution = 0.5\nfriction = 0.1\nrace_inertia = 1.0e-4\n")
    return text + "[operating]\nspeed_rpm = 3000.0\n"


def test_drop_writes_its_summary_and_figure(tmp_path, capsys):
    """At the rig's speed: one JSON object with each plane's peak force, penetration and
    regime (the first impact's penetration below the clearance, the journal's orbit at
    least the clearance), the drop.json and drop.png it names; the same numbers in the
    file."""
    rig = tmp_path / "rig.toml"
    rig.write_text(_rig_text())
    out = tmp_path / "drop"
    code = main(["--quiet", "drop", str(rig), "--duration-s", "0.03", "--out", str(out),
                 "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 0
    assert doc["speed_rpm"] == 3000.0 and doc["speed_rad_s"] == pytest.approx(100 * math.pi)
    assert [p["name"] for p in doc["planes"]] == ["TA", "TB"]
    for p in doc["planes"]:
        assert p["peak_force_n"] > 0 and 0 < p["max_penetration_m"] < 2e-4
        assert p["max_orbit_m"] >= 2e-4
        assert p["regime"] in ("bouncing", "resting", "forward whirl", "backward whirl",
                               "no contact")
    assert set(doc["watched_max_m"]) == {"amb:A", "amb:B"}
    assert json.loads((out / "drop.json").read_text())["planes"] == doc["planes"]
    assert doc["files"] == [str(out / f) for f in ("drop.json", "drop.png", "drop_whirl.png",
                                                    "drop_currents.png", "drop.html")]
    assert (out / "drop.png").stat().st_size > 0 and (out / "drop_whirl.png").stat().st_size
    # the page: the verdict first, then each bearing's row with its numbers, the figures
    # embedded
    page = (out / "drop.html").read_text()
    assert page.index("<h2>Verdict</h2>") < page.index("<h2>Touchdown bearings</h2>")
    assert doc["verdict"] in page and page.count("data:image/png;base64,") == 3
    # each watched plane's gap beside its excursion, and their ratio
    assert doc["gaps_m"] == {"amb:A": 5e-4, "amb:B": 5e-4}
    ratio = doc["watched_max_m"]["amb:A"] / 5e-4
    assert "excursion / gap" in page and f"<td>{ratio:.3g}</td>" in page
    for p in doc["planes"]:
        assert f"{p['peak_force_n']:.4g}" in page
        assert f"{1e6 * p['max_orbit_m']:.4g} ({p['max_orbit_m'] / 2e-4:.3g} c)" in page


def test_a_rig_without_touchdown_bearings_is_refused(tmp_path, capsys):
    rig = tmp_path / "rig.toml"
    rig.write_text(_rig_text(touchdown=False))
    code = main(["drop", str(rig), "--out", str(tmp_path / "d")])
    err = capsys.readouterr().err
    assert code == 2 and "[[touchdown]]" in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


def test_drop_coasting_down(tmp_path, capsys):
    """``--coast-down --drag-torque 2``: the spin the JSON ends with is below the start;
    a drag torque without the coast-down is refused by name (exit 2)."""
    rig = tmp_path / "rig.toml"
    rig.write_text(_rig_text())
    code = main(["--quiet", "drop", str(rig), "--duration-s", "0.02", "--out",
                 str(tmp_path / "d"), "--json", "--coast-down", "--drag-torque", "2"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 0 and doc["final_speed_rad_s"] < doc["speed_rad_s"]
    code = main(["drop", str(rig), "--out", str(tmp_path / "e"), "--drag-torque", "2"])
    err = capsys.readouterr().err
    assert code == 2 and "--drag-torque" in err and "Traceback" not in err


EXAMPLES = sorted(Path(__file__).resolve().parents[1].glob("examples/*.toml"))


@pytest.mark.heavy
@pytest.mark.parametrize("rig", EXAMPLES, ids=lambda p: p.stem)
def test_every_example_rig_lands_on_its_own_touchdown_bearings(rig, tmp_path, capsys):
    """Each example carries two touchdown bearings and drops onto them at its operating
    speed: a verdict (exit 0 or 1, never a refusal), the first impact's penetration a
    small fraction of the clearance, and the journal at least the clearance off centre
    at each plane it lands on — every plane but where a stiff seal holds the rotor up
    (the turboexpander's hole-pattern seal, 12 MN/m at its speed, holds the end near
    it off its ring: that plane is "no contact"). A standing example (the flywheel)
    lands on its lower plane's axial face, within its axial clearance, and, balanced,
    touches no ring radially."""
    cfg = load_rig(rig)
    assert len(cfg.touchdown) == 2
    code = main(["--quiet", "drop", str(rig), "--duration-s", "0.04", "--out",
                 str(tmp_path), "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert code in (0, 1) and doc["verdict"].startswith("Drop ")
    assert doc["speed_rpm"] == cfg.operating.speed_rpm and doc["impacts"] >= 2
    if cfg.machine.orientation == "vertical":
        stops = [p for p, td in zip(doc["planes"], cfg.touchdown) if td.axial_clearance]
        assert stops and all(p["peak_axial_force_n"] > 0 for p in stops)
        assert all(0 < p["max_axial_penetration_m"] < 0.2 * td.axial_clearance
                   for p, td in zip(doc["planes"], cfg.touchdown) if td.axial_clearance)
        assert all(p["peak_force_n"] == 0 for p in doc["planes"])
        return
    held = {"turboexpander": {"TA"}}.get(rig.stem, set())
    for p, td in zip(doc["planes"], cfg.touchdown):
        assert p["name"] == td.name
        if td.name in held:
            assert p["regime"] == "no contact" and p["max_orbit_m"] < td.radial_clearance
            continue
        assert p["peak_force_n"] > 0
        assert 0 < p["max_penetration_m"] < 0.2 * td.radial_clearance
        assert p["max_orbit_m"] >= td.radial_clearance


def test_monte_carlo_drops_from_the_command_line(tmp_path, capsys):
    """``--runs 3 --seed 5 --friction 0.1:0.2 --unbalance-kgm 0:1e-4``: the JSON's counts,
    the CSV of the three runs with their draws, the same numbers again for the same seed;
    a spread without ``--runs``, or an unbalance range for one drop, refused by name."""
    rig = tmp_path / "rig.toml"
    rig.write_text(_rig_text())
    args = ["--quiet", "drop", str(rig), "--duration-s", "0.02", "--runs", "3", "--seed",
            "5", "--friction", "0.1:0.2", "--unbalance-kgm", "0:1e-4", "--workers", "1",
            "--json"]
    code = main([*args, "--out", str(tmp_path / "a")])
    doc = json.loads(capsys.readouterr().out)
    assert code in (0, 1) and (code == 1) == (doc["failed"]["count"] > 0)
    assert doc["n"] == 3 and doc["seed"] == 5 and "runs" not in doc
    lines = (tmp_path / "a" / "drop_scatter.csv").read_text().splitlines()
    assert len(lines) == 4 and "TA_friction" in lines[0]
    main([*args, "--out", str(tmp_path / "b")])
    capsys.readouterr()
    assert (tmp_path / "b" / "drop_scatter.csv").read_text() == "\n".join(lines) + "\n"
    for extra, key in ((["--friction", "0.1:0.2"], "--friction"),
                       (["--unbalance-kgm", "0:1e-4"], "--unbalance-kgm")):
        code = main(["drop", str(rig), "--out", str(tmp_path / "c"), *extra])
        err = capsys.readouterr().err
        assert code == 2 and key in err and "Traceback" not in err
    with pytest.raises(SystemExit) as stop:  # argparse's own refusal
        main(["drop", str(rig), "--runs", "2", "--friction", "0.3:0.1"])
    assert stop.value.code == 2 and "--friction" in capsys.readouterr().err


@pytest.mark.parametrize("at, rpm", [("standstill", 0.0), ("max-continuous", 3000.0),
                                     ("trip", 3150.0)])
def test_the_drop_at_a_named_speed(at, rpm, tmp_path, capsys):
    """``--at``: standstill, the maximum continuous speed (the rig's 3 000 rpm, no range
    given) and the trip speed (API 617's 105 % where the rig gives none)."""
    rig = tmp_path / "rig.toml"
    rig.write_text(_rig_text())
    code = main(["--quiet", "drop", str(rig), "--at", at, "--duration-s", "0.01",
                 "--out", str(tmp_path / "d"), "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert code in (0, 1) and doc["speed_rpm"] == pytest.approx(rpm)
    assert doc["speed_rad_s"] == pytest.approx(rpm * math.pi / 30)


def test_an_unbalanced_drop_starts_from_its_levitated_orbit_or_at_rest(tmp_path, capsys):
    """``--unbalance-kgm``: by default the drop starts in the reference PID loop's
    unbalance orbit, with ``--start rest`` from the levitated equilibrium at rest; the
    JSON says which, and the two drops differ."""
    rig = tmp_path / "rig.toml"
    rig.write_text(_rig_text())
    docs = {}
    for start in ("levitated", "rest"):
        code = main(["--quiet", "drop", str(rig), "--duration-s", "0.02", "--unbalance-kgm",
                     "2e-3", "--start", start, "--out", str(tmp_path / start), "--json"])
        docs[start] = json.loads(capsys.readouterr().out)
        assert code in (0, 1) and docs[start]["start"] == start
        assert docs[start]["unbalance_kgm"] == 2e-3
    assert docs["levitated"]["planes"] != docs["rest"]["planes"]
    # from its orbit the reference PID held the rotor; from rest, every axis lost, no
    # controller acts on the drop and none is derived
    assert docs["levitated"]["controller"] == "reference PID"
    assert docs["rest"]["controller"] == "none: every axis lost at rest"
    assert docs["rest"]["controller_runs"] is None


@pytest.mark.heavy
def test_the_events_from_the_command_line(tmp_path, capsys):
    """``--event one-axis`` loses the most loaded axis by default (a vertical one; here
    both AMBs alike, the first), lands its end, the other AMB taking up more of the
    weight; ``--event overload`` beyond the AMBs' capacity (each holds
    Ki·i_max = 500 N) lands both ends and says the currents saturated, one within it
    does not land (5 N on the reference PID's 1e5 N/m); arguments of another event, a
    controller for Monte-Carlo drops and a bad event with --runs are refused."""
    rig = tmp_path / "rig.toml"
    rig.write_text(_rig_text())

    def drop(*extra):
        code = main(["--quiet", "drop", str(rig), "--duration-s", "0.05", "--start", "rest",
                     "--speed-rpm", "0", "--out", str(tmp_path / "d"), "--force", "--json",
                     *extra])
        return code, json.loads(capsys.readouterr().out)

    code, doc = drop("--event", "one-axis")
    assert code == 0 and doc["event"] == "one-axis"
    assert [a["channel"] for a in doc["amb"] if a["failed"]] == ["A_eta"]
    # A's end lands; B's axis takes up more than its static share, m g/(2 Ki)
    assert doc["planes"][0]["peak_force_n"] > 0
    static = (20.0 + 7850.0 * math.pi / 4 * 0.1 ** 2 * L) * 9.80665 / 2 / 100.0
    assert doc["amb"][3]["peak_current_a"] > 1.2 * static
    code, doc = drop("--event", "overload", "--overload-n", "1500")
    assert [p["peak_force_n"] > 0 for p in doc["planes"]] == [True, True]
    assert [a["saturated"] for a in doc["amb"]] == [False, True, False, True]
    assert "1500 N downward at centre of mass" in doc["event_summary"]
    code, doc = drop("--event", "overload", "--overload-n", "5", "--overload-at", "A")
    assert [p["regime"] for p in doc["planes"]] == ["no contact", "no contact"]
    for bad, why in ((["--axis", "A_eta"], "--axis: names the axis of --event one-axis"),
                     (["--event", "one-axis", "--axis", "C_eta"], "--axis: expected one of"),
                     (["--event", "overload"], "--overload-n: expected the step force"),
                     (["--event", "overload", "--overload-n", "1", "--overload-at", "X"],
                      "--overload-at: expected a seal, AMB"),
                     (["--runs", "2", "--controller", "pid"],
                      "--controller: Monte-Carlo drops run the reference PID"),
                     (["--event", "overload", "--runs", "2"],
                      "--overload-n: expected the step force")):
        assert main(["--quiet", "drop", str(rig), "--out", str(tmp_path / "x"), *bad]) == 2
        err = capsys.readouterr().err
        assert why in err and "Traceback" not in err


def test_the_drop_from_a_designed_controllers_orbit(tmp_path, capsys):
    """``--controller FILE``: the loop a drop starts from and runs on is the file's
    controller: a PID twice as stiff as the rig's reference PID holds an unbalance to a
    smaller orbit at the instant of the drop (the levitated start, as its closed form in
    test_analysis_drop), named in drop.json."""
    from ambseal.design import pid_controller, reference_pid
    from ambseal.export import export_controller
    from ambseal.model import channel_names

    rig = tmp_path / "rig.toml"
    rig.write_text(_rig_text())
    cfg = load_rig(rig)
    g = reference_pid(cfg)
    stiff = export_controller(pid_controller(2 * g["kp"], g["ti"], g["td"], g["eps"],
                                             channel_names(cfg)), tmp_path / "stiff.json")
    orbits = []
    for extra in ([], ["--controller", str(stiff)]):
        code = main(["--quiet", "drop", str(rig), "--duration-s", "0.002", "--event",
                     "one-axis", "--unbalance-kgm", "1e-3", "--out",
                     str(tmp_path / "d"), "--force", "--json", *extra])
        doc = json.loads(capsys.readouterr().out)
        assert code in (0, 1)
        orbits.append(doc["watched_max_m"]["amb:B"])
    assert doc["controller"] == str(stiff)
    assert orbits[1] < orbits[0]


def test_the_seals_drop_with_the_rotor_at_their_pressure(tmp_path, capsys):
    """A seal whose cross-coupled stiffness grows with its pressure drop (k = 2e3 N/m per
    bar) changes the levitated orbit the rotor drops from: at ``--pressure-bar 20`` the
    largest excursion at the seal differs from that at 0 bar, and drop.json says the
    pressure; a negative one is refused (exit 2)."""
    rig = tmp_path / "rig.toml"
    rig.write_text(_rig_text() + f'[[seal]]\nname = "mid"\nposition = {L / 2}\n'
                   "clearance = 3.0e-4\nk = { per_bar = 2.0e3 }\n")
    seen = {}
    for bar in ("0", "20"):
        assert main(["--quiet", "drop", str(rig), "--duration-s", "0.001",
                     "--unbalance-kgm", "1e-3", "--pressure-bar", bar, "--out",
                     str(tmp_path / "d"), "--force", "--json"]) in (0, 1)
        doc = json.loads(capsys.readouterr().out)
        assert doc["pressure_bar"] == float(bar)
        seen[bar] = doc["watched_max_m"]["seal:mid"]
    assert abs(seen["20"] - seen["0"]) > 1e-3 * seen["0"]
    assert main(["--quiet", "drop", str(rig), "--pressure-bar", "-1", "--out",
                 str(tmp_path / "x")]) == 2
    assert "--pressure-bar: expected a value >= 0.0, got -1.0" in capsys.readouterr().err


@pytest.mark.heavy
def test_a_seal_surge_lands_a_rotor_its_loop_held(tmp_path, capsys):
    """``--event overload --surge-bar P``: the seal's pressure drop steps from the
    operating 0 bar to 3000 bar at the event, its cross-coupled stiffness (2e3 N/m per
    bar) with it to 6e6 N/m, fifteen times what the reference PID's damping holds at the
    rigid forward whirl (its loop's pole then grows at 204/s): the loop that held the
    rotor in its orbit no longer does, and the rotor lands; at 0 bar, with a 1 N step
    only, it stays clear. A negative surge is refused by the rule of ``[operating]
    pressure_bar`` (exit 2)."""
    rig = tmp_path / "rig.toml"
    rig.write_text(_rig_text() + f'[[seal]]\nname = "mid"\nposition = {L / 2}\n'
                   "clearance = 3.0e-4\nk = { per_bar = 2.0e3 }\n")
    peaks = {}
    for extra in (["--surge-bar", "3000"], ["--overload-n", "1"]):
        assert main(["--quiet", "drop", str(rig), "--duration-s", "0.06", "--event",
                     "overload", "--unbalance-kgm", "1e-4", "--out", str(tmp_path / "d"),
                     "--force", "--json", *extra]) in (0, 1)
        doc = json.loads(capsys.readouterr().out)
        peaks[extra[0]] = max(p["peak_force_n"] for p in doc["planes"])
        assert ("surging from 0 to 3000 bar" in doc["event_summary"]) == (
            extra[0] == "--surge-bar")
    assert peaks["--surge-bar"] > 0 and peaks["--overload-n"] == 0
    assert main(["--quiet", "drop", str(rig), "--event", "overload", "--surge-bar", "-1",
                 "--out", str(tmp_path / "x")]) == 2
    assert ("--surge-bar: expected a value >= 0.0, got -1.0 (the rule of [operating] "
            "pressure_bar") in capsys.readouterr().err


def test_the_thrust_drives_the_rotor_onto_its_axial_stop(tmp_path, capsys):
    """``--axial-thrust-n`` overrides ``[drop] axial_thrust``: the rotor, let go by every
    axis, moves axially onto the plane with an ``axial_clearance`` and the JSON and the
    page give its axial force, excursion and friction heat; with the thrust reversed the
    rotor leaves its stop the other way, by the same clearance; with an event that keeps
    the thrust bearing the flag is refused in one line (exit 2)."""
    text = _rig_text().replace('name = "TB"\n', 'name = "TB"\naxial_clearance = 1.0e-4\n'
                                                'race_mass = 0.05\n')
    rig = tmp_path / "rig.toml"
    rig.write_text(text)
    docs = []
    for thrust in ("2000", "-2000"):
        out = tmp_path / f"drop{thrust}"
        code = main(["--quiet", "drop", str(rig), "--duration-s", "0.01", "--out", str(out),
                     "--json", "--axial-thrust-n", thrust])
        docs.append(json.loads(capsys.readouterr().out))
        assert code == 0
    for doc, sign in zip(docs, (1, -1)):
        assert doc["axial_thrust_n"] == sign * 2000.0
        ta, tb = doc["planes"]
        assert ta["peak_axial_force_n"] == 0 and tb["peak_axial_force_n"] > 2000.0
        assert 1e-4 < doc["max_axial_m"] < 1.5e-4
        assert tb["friction_heat_j"] > 0
    page = (tmp_path / "drop2000" / "drop.html").read_text()
    assert "peak axial force (N)" in page and "the thrust bearing let go" in page
    assert "ring temperature rise at TB" in page
    code = main(["--quiet", "drop", str(rig), "--event", "one-axis", "--duration-s", "0.01",
                 "--out", str(tmp_path / "x"), "--axial-thrust-n", "100"])
    err = capsys.readouterr().err
    assert code == 2 and "--axial-thrust-n" in err and "Traceback" not in err


@pytest.mark.heavy
def test_monte_carlo_drops_of_an_event(tmp_path, capsys):
    """``--runs`` with ``--event overload``: every run is the overload beyond the AMBs'
    capacity from the reference PID's orbit (both ends land in each, whatever its
    friction), one within it lands neither, ``--event one-axis`` lands A's end (B's end,
    the rotor tilting about B's running axis, may touch its ring too); the JSON names the
    event."""
    rig = tmp_path / "rig.toml"
    rig.write_text(_rig_text())
    for k, (extra, landed) in enumerate((
            (["--event", "overload", "--overload-n", "1500"], {"TA": True, "TB": True}),
            (["--event", "overload", "--overload-n", "5"], {"TA": False, "TB": False}),
            (["--event", "one-axis"], {"TA": True}))):
        code = main(["--quiet", "drop", str(rig), "--duration-s", "0.03", "--speed-rpm", "0",
                     "--runs", "2", "--seed", "3", "--friction", "0.05:0.3", "--workers",
                     "1", "--json", "--out", str(tmp_path / str(k)), *extra])
        doc = json.loads(capsys.readouterr().out)
        assert code in (0, 1) and doc["event"] == extra[1] and doc["n"] == 2
        rows = (tmp_path / str(k) / "drop_scatter.csv").read_text().splitlines()
        head = rows[0].split(",")
        for row in rows[1:]:
            cells = dict(zip(head, row.split(",")))
            assert {p: float(cells[f"{p}_peak_force_n"]) > 0 for p in landed} == landed


def test_a_standing_rotors_drop_lands_it_axially_and_says_so(tmp_path, capsys):
    """A vertical rig whose touchdown planes have no ``axial_clearance``: the drop warns
    on stderr that the weight along the axis stays on the thrust bearing (its axial
    landing not modelled); with an axial clearance on the lower plane it says nothing
    of it and the rotor lands on that face, its JSON and text output naming the
    orientation; a horizontal rig's drop warns of nothing and lands on its rings."""
    axial = "axial_clearance = 1.0e-4\n"
    for name, orientation, stop, said in (("bare", "vertical", "", True),
                                          ("stop", "vertical", axial, False),
                                          ("lying", "horizontal", "", False)):
        text = _rig_text().replace("position = 0.0\n", "position = 0.0\n" + stop, 1)
        rig = tmp_path / f"{name}.toml"
        rig.write_text(text + f'[drop]\naxial_thrust = 0.0\n[machine]\norientation = '
                       f'"{orientation}"\n')
        code = main(["--quiet", "drop", str(rig), "--duration-s", "0.01", "--speed-rpm",
                     "0", "--out", str(tmp_path / name), "--json"])
        captured = capsys.readouterr()
        doc = json.loads(captured.out)
        assert code in (0, 1)
        assert ('orientation = "vertical"' in captured.err
                and "axial_clearance" in captured.err) == said
        assert doc["orientation"] == orientation
        assert doc["orientation_note"].startswith(f"{orientation} machine")
        ta = doc["planes"][0]
        if name == "stop":  # on its face, nowhere near its rings
            assert ta["peak_axial_force_n"] > 0
            assert all(p["peak_force_n"] == 0 for p in doc["planes"])
        if name == "lying":
            assert ta["peak_force_n"] > 0 and ta["peak_axial_force_n"] == 0
    main(["--quiet", "drop", str(tmp_path / "stop.toml"), "--duration-s", "0.001",
          "--speed-rpm", "0", "--out", str(tmp_path / "text")])
    assert "vertical machine: its weight along the axis" in capsys.readouterr().out
