"""ambseal.export: controllers to files a real-time target runs, and back.

* :func:`export_controller`, :func:`load_controller` — ``.json``, ``.npz`` and ``.mat``
  files holding the discrete controller as it was judged
  (:mod:`ambseal.export.controller_files`);
* :func:`write_c` — a portable C99 header and source of the same controller
  (:mod:`ambseal.export.codegen`); :func:`c_identifier` — a name as a C identifier;
* :func:`export_notch`, :func:`load_notch`, :func:`write_notch_c` — a controller's
  unbalance force rejection (its synchronous notch) as a file and as C
  (:mod:`ambseal.export.notch_files`).
"""

from ambseal.export.codegen import c_identifier, write_c, write_notch_c
from ambseal.export.controller_files import export_controller, load_controller, loop_verdict
from ambseal.export.notch_files import export_notch, load_notch

__all__ = ["c_identifier", "export_controller", "load_controller", "loop_verdict", "write_c",
           "export_notch", "load_notch", "write_notch_c"]
