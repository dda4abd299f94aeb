"""The reader of an identification's ``fit.json`` (identify/fitting/intervals.py) on files
edited by hand or damaged: a field of the wrong type anywhere is refused with one error
naming the file and the field — through ``[design] uncertainty_from_identification`` by
``ambseal validate`` and ``ambseal design`` with exit status 2 and one line — and a property
test (hypothesis) over mutated fits, as the ROSS 3 reader is fuzzed
(tests/io/test_io_ross3_file.py): a damaged fit is refused naming the file, or read to the
intervals it holds."""

from __future__ import annotations

import contextlib
import copy
import io
import json
import math
import tempfile
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings

from ambseal.cli import main
from ambseal.errors import DataError
from ambseal.identify.fitting.intervals import uncertainty_from_fit

from ..conftest import ROOT
from ..mutations import mutated
from ..toml_text import dump

#: A fit as ``ambseal identify`` writes it (FitResult.to_dict and the command's keys): two
#: fitted parameters and τ_e, the error budget of one held value (disputed, within 1.96 σ
#: of its stated uncertainty), the residual tests and the sensor-lag test, none flagged.
FIT = {
    "parameters": {
        "seal.k": {"estimate": 2.2e6, "initial": 2.0e6, "std_error": 1.5e5,
                   "std_error_noise": 1.2e5, "dof_noise": 812.0, "ci95": [1.9e6, 2.5e6]},
        "A.Ki_zeta": {"estimate": 101.0, "initial": 100.0, "std_error": 1.1,
                      "std_error_noise": 1.0, "ci95": [98.8, 103.2]},
        "tau_e": {"estimate": 2e-4, "initial": 1e-4, "std_error": 1e-5,
                  "std_error_noise": 1e-5, "ci95": [None, None]},
    },
    "correlation": [[1.0, 0.2, 0.1], [0.2, 1.0, 0.0], [0.1, 0.0, 1.0]],
    "nrmse_fit_pct": {"A_zeta": 3.1, "B_eta": 2.9},
    "converged": True, "message": "converged", "iterations": 7, "wall_time_s": 1.5,
    "error_budget": {
        "fixed": {"coupling.kxx": {"sigma_rel": 0.05, "source": "stated"}},
        "std_error_contribution": {"seal.k": {"coupling.kxx": 3e4}},
        "variance_share": {"seal.k": {"coupling.kxx": 0.04}},
        "dominant": ["coupling.kxx"],
        "score_test": {"coupling.kxx": {"z": 7.0, "offset_rel": 0.09, "offset_rel_se": 0.01}},
        "disputed": ["coupling.kxx"],
    },
    "residual_tests": {"test": "Ljung §16.6", "lags": 20, "ar_order": 8, "block_samples": 4000,
                       "channels": {"A_zeta": {"whiteness": 30.0, "whiteness_limit": 37.6,
                                               "white": True, "independence": 20.0,
                                               "independence_limit": 37.6,
                                               "independent": True}},
                       "mismatch": False, "verdict": "residuals independent of the excitation"},
    "model_check": {"residuals_correlated": [], "disputed": [], "sensor_lag": False,
                    "mismatch": False, "verdict": "no mismatch found"},
    "sensor_lag_test": {"test": "score test", "suggested_tau_s": 1e-6,
                        "suggested_tau_s_se": 2e-6, "flagged": False},
    "warnings": [],
}


def _call(args: list[str]) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            code = main(args)
        except SystemExit as exc:  # argparse
            code = exc.code
    return code, err.getvalue()


def test_the_fit_read_as_written(tmp_path):
    """Reference: the fit's own intervals — the undamaged fit gives its two model
    parameters' ci95 (τ_e, whose interval failed, left out), unchanged."""
    path = tmp_path / "fit.json"
    path.write_text(json.dumps(FIT))
    assert uncertainty_from_fit(path) == {"seal.k": (1.9e6, 2.5e6), "A.Ki_zeta": (98.8, 103.2)}


@pytest.mark.parametrize("command", [["validate"], ["design", "--method", "pid"]])
def test_a_list_in_a_field_of_the_fit_is_refused_naming_file_and_field(tmp_path, command):
    """The reproducer: ``residual_tests = [1]`` in the fit a rig designs on ends
    ``ambseal validate`` and ``ambseal design`` in exit 2 with one line naming the fit file
    and the field, and what was expected."""
    fit = tmp_path / "fit_list.json"
    fit.write_text(json.dumps({"parameters": {"seal.k": {"ci95": [1.0, 2.0e6]}},
                               "residual_tests": [1]}))
    doc = tomllib.loads((ROOT / "examples" / "testrig.toml").read_text())
    doc.setdefault("design", {})["uncertainty_from_identification"] = fit.name
    rig = tmp_path / "rig.toml"
    rig.write_text(dump(doc))
    code, err = _call([*command[:1], str(rig), *command[1:], "--out", str(tmp_path / "o")]
                      if command[0] == "design" else [*command, str(rig)])
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    assert lines[0].startswith("ambseal: error: ")
    assert f"{fit}: residual_tests: expected a table, got list [1]" in lines[0]


@pytest.mark.parametrize(("edit", "field"), [
    (lambda d: d["parameters"].update({"seal.k": [1.9e6, 2.5e6]}), "parameters.seal.k"),
    (lambda d: d["parameters"]["seal.k"].update(ci95="1.9e6"), "parameters.seal.k.ci95"),
    (lambda d: d["parameters"]["seal.k"].update(ci95=[True, 2.5e6]),
     r"parameters.seal.k.ci95\[0\]"),
    (lambda d: d.update(model_check=["sensor_lag"]), "model_check"),
    (lambda d: d["model_check"].update(sensor_lag="no"), "model_check.sensor_lag"),
    (lambda d: d.update(sensor_lag_test="flagged"), "sensor_lag_test"),
    (lambda d: d["residual_tests"].update(mismatch=0), "residual_tests.mismatch"),
    (lambda d: d.update(error_budget=[]), "error_budget"),
    (lambda d: d["error_budget"].update(disputed={"coupling.kxx": 1}),
     "error_budget.disputed"),
    (lambda d: d["error_budget"].update(fixed=[0.05]), "error_budget.fixed"),
    (lambda d: d["error_budget"]["fixed"]["coupling.kxx"].update(sigma_rel="5 %"),
     "error_budget.fixed.coupling.kxx.sigma_rel"),
    (lambda d: d["error_budget"]["score_test"].update({"coupling.kxx": 0.09}),
     "error_budget.score_test.coupling.kxx"),
])
def test_every_field_read_is_checked_for_its_type(tmp_path, edit, field):
    """Reference: the fields the reader uses (FitResult.to_dict's types) — a wrong type in
    any of them is a DataError naming the file and the field's path, never an
    AttributeError or TypeError."""
    doc = copy.deepcopy(FIT)
    edit(doc)
    path = tmp_path / "fit.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(DataError, match=rf"^{path}: {field}: expected "):
        uncertainty_from_fit(path)


@settings(max_examples=300, deadline=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
@given(doc=mutated(FIT))
def test_a_damaged_fit_is_refused_naming_the_file_or_read_as_it_holds(doc):
    """Property (hypothesis) over the fit's layout, 1–3 mutations each (a key deleted, a
    value replaced by one of another type or non-finite, a number scaled, an entry
    duplicated): the reader refuses it with a DataError naming the file, or returns, for
    each parameter but τ_e, exactly the fit's finite [low, high] with low < high — never
    another exception."""
    # a folder per example, removed with it: hypothesis runs hundreds
    with tempfile.TemporaryDirectory(prefix="ambseal-test-") as folder:
        path = Path(folder) / "fit.json"
        path.write_text(json.dumps(doc))  # NaN and Infinity as Python's json writes them
        try:
            got = uncertainty_from_fit(path)
        except DataError as exc:
            assert str(exc).startswith(f"{path}: "), exc
            return
    params = doc["parameters"]
    assert list(got) == [n for n in params if n != "tau_e"]
    for n, (lo, hi) in got.items():
        assert [lo, hi] == params[n]["ci95"] and math.isfinite(lo) and lo < hi

