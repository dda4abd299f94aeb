"""ambseal.app: the commands as a user runs them — wiring only, no numerics.

* :mod:`ambseal.app.pipeline` — ``ambseal run``, the main job stage by stage;
* :mod:`ambseal.app.commands` — ``design``, ``identify``, ``validate``, ``track`` and the
  main job's stages that write files;
* :mod:`ambseal.app.rotordynamics` — ``campbell``, ``sweep``, ``import-ross``, and
  :mod:`ambseal.app.modes` — ``modes``;
* :mod:`ambseal.app.tracked` — the main job's controller scheduled on the tracked seal.

The command line itself is :mod:`ambseal.cli`; it runs a command through :data:`HANDLERS`
(:mod:`ambseal.app.handlers`: the command's name → its handler), and ``modes`` through
:func:`modes_command` (:mod:`ambseal.app.modes` alone: a quick look at a model loads none
of the other commands' python-control and numba). The names load on first use (PEP 562
``__getattr__``, ``ambseal.lazy.lazy_face``), so that ``import ambseal.app`` — and the
command line's ``--help`` — loads none of the commands' numerics.
"""

from ambseal.lazy import lazy_face

#: Each public name (``__all__``) and the module that defines it.
_FROM = {"HANDLERS": "handlers", "modes_command": "modes"}

__all__ = sorted(_FROM)

__getattr__, __dir__ = lazy_face(__name__, _FROM)
