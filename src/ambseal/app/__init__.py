"""ambseal.app: the commands as a user runs them — wiring only, no numerics.

* :mod:`ambseal.app.pipeline` — ``ambseal run``, the main job stage by stage;
* :mod:`ambseal.app.commands` — ``design``, ``identify``, ``validate``, ``track`` and the
  main job's stages that write files;
* :mod:`ambseal.app.rotordynamics` — ``modes``, ``campbell``, ``sweep``, ``import-ross``;
* :mod:`ambseal.app.tracked` — the main job's controller scheduled on the tracked seal.

The command line itself is :mod:`ambseal.cli`.
"""
