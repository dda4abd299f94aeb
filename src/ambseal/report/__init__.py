"""ambseal.report: figures (matplotlib, Agg) and the self-contained HTML report.

* :func:`write_run_report`, :func:`stamp`, :func:`judged_on`, :func:`statics_section` —
  the main job's ``report.html`` (:mod:`ambseal.report.run_report`), its figures
  (:func:`gains_figure`, :func:`capacity_figure`, :func:`rejection_figure`,
  :func:`spinup_figures`) and sections
  (:func:`identification_report`, :func:`facility_impulse_report`);
* :func:`verdicts`, :func:`verdict_table_rich`, :func:`target_difference` — the verdict
  per controller (:mod:`ambseal.report.verdict`);
* :func:`campbell_figure`, :func:`mode_shapes_figure`, :func:`stability_map_figure` —
  rotordynamics (:mod:`ambseal.report.modal_figures`);
* :func:`fit_timeseries_figure`, :func:`correlation_figure`, :func:`residual_figure`,
  :func:`error_budget_figure` — an identification (:mod:`ambseal.report.identify_figures`);
* :func:`tracking_figure`, :func:`ramp_figure` — on-line tracking and the pressure ramp;
* :func:`level1_figure`, :func:`api617_unbalance_figure`, :func:`ucs_map_figure`,
  :func:`signoff_report` — API 617's Level I screening, unbalance response, API 684's
  undamped critical speed map (:mod:`ambseal.report.signoff_figures`);
* :func:`drop_figure`, :func:`drop_whirl_figure`, :func:`drop_current_figure` — the
  rotor drop: the AMB axes' currents, orbits in the
  clearance, contact forces, the whirl's waterfall (:func:`whirl_waterfall`), the rings'
  speeds
  (:mod:`ambseal.report.drop_figures`); :func:`write_drop_report`, its page
  (:mod:`ambseal.report.drop_report`);
* :func:`figure_is_ours` — whether a PNG is one ambseal wrote (:mod:`ambseal.report.figures`);
* :class:`StageProgress` — a long job's progress, stage by stage.

The names load on first use (PEP 562 ``__getattr__``, ``ambseal.lazy.lazy_face``), so
``import ambseal.report`` does not load matplotlib.
"""

from ambseal.lazy import lazy_face

#: Each public name (``__all__``) and the module that defines it.
_FROM = {
    "figure_is_ours": "figures",
    "correlation_figure": "identify_figures", "error_budget_figure": "identify_figures",
    "fit_timeseries_figure": "identify_figures", "residual_figure": "identify_figures",
    "campbell_figure": "modal_figures", "mode_shapes_figure": "modal_figures",
    "stability_map_figure": "modal_figures",
    "StageProgress": "progress",
    "level1_figure": "signoff_figures", "signoff_report": "signoff_figures",
    "drop_figure": "drop_figures", "drop_whirl_figure": "drop_figures",
    "whirl_waterfall": "drop_figures", "drop_current_figure": "drop_figures",
    "write_drop_report": "drop_report",
    "api617_unbalance_figure": "signoff_figures", "ucs_map_figure": "signoff_figures",
    "facility_impulse_report": "run_report", "gains_figure": "run_report",
    "capacity_figure": "run_report", "rejection_figure": "run_report",
    "identification_report": "run_report", "judged_on": "run_report",
    "spinup_figures": "run_report",
    "stamp": "run_report", "write_run_report": "run_report",
    "statics_section": "run_report",
    "ramp_figure": "tracking_figures", "tracking_figure": "tracking_figures",
    "target_difference": "verdict", "verdict_table_rich": "verdict", "verdicts": "verdict",
}

__all__ = sorted(_FROM)

__getattr__, __dir__ = lazy_face(__name__, _FROM)
