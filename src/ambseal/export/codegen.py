"""Portable C99 code of a digital controller: a header and a source, no dynamic memory.

The module implements exactly the discrete controller that was judged and exported
(:class:`~ambseal.robust.digital.DigitalController`, or the table of a
:class:`~ambseal.machine.scheduled_digital.ScheduledDigital`), in ``double`` or ``float``::

    #include "ambseal_hinf.h"
    ambseal_hinf_state s;
    ambseal_hinf_reset(&s);
    /* every sample: y = sensor displacements (m), i = current references (A) */
    ambseal_hinf_step(&s, y, i);            /* scheduled: ambseal_lpv_step(&s, speed_rad_s, y, i) */

(a controller scheduled on a seal coefficient takes ``theta``, its tracked value in SI, in
place of ``speed_rad_s``; a controller's unbalance force rejection is a module of its own,
:func:`write_notch_c`, whose output the controller reads in place of ``y``)

``step`` computes ``i[k] = −(C x[k] + D y[k])`` (the sign convention ``i = −K y`` applied
inside), then ``x[k+1] = A x[k] + B y[k]``. The state-space form is the real Schur
realisation of the controller (an orthogonal similarity, so it is backward stable and keeps
the conditioning of the realisation; ``A`` is quasi upper-triangular and the loop skips its
zeros; Golub & Van Loan §7.4). A scheduled controller uses one orthogonal basis for the whole
table (the Schur basis of its middle entry), so the linear interpolation on θ —
the same law as in Python — stays exact. The computation delay of the target is not in the
code: it is the time between reading ``y`` and writing ``i`` on the target itself.

Only the prefix becomes C identifiers, and it must match ``[A-Za-z_][A-Za-z0-9_]*``
(:func:`c_identifier` maps a file name to one). Every name that comes with the controller
(its name, signals, scheduling parameter, method) is text from a file: in comments it is
printable ASCII with ``*/``, ``/*`` and ``??`` broken apart and anything else written as
``<U+XXXX>``, and the controller's name is kept as an escaped string literal
(``<PREFIX>_NAME``).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import scipy.linalg as sla

from ambseal.errors import ConfigError
from ambseal.files import write_text
from ambseal.machine import SPEED, ScheduledDigital

__all__ = ["write_c", "write_notch_c", "schur_realisation", "c_identifier"]

_PRECISION = {"double": ("double", ""), "float": ("float", "f")}
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def c_identifier(text: str) -> str:
    """``text`` mapped to a C identifier (``[A-Za-z_][A-Za-z0-9_]*``).

    Parameters
    ----------
    text : str
        Any name, e.g. a controller file's stem.

    Returns
    -------
    str
        ``text`` with every character outside ``[A-Za-z0-9_]`` replaced by ``_``, and
        ``_`` in front of a leading digit or of an empty name.

    Examples
    --------
    >>> c_identifier("K-1.v2")
    'K_1_v2'
    """
    out = re.sub(r"[^A-Za-z0-9_]", "_", str(text))
    return "_" + out if not out or out[0].isdigit() else out


#: The field's symbols a verdict or a name carries, spelled in ASCII for a C comment.
_ASCII = {"ζ": "zeta", "η": "eta", "μ": "mu", "γ": "gamma", "∞": "inf", "Ω": "Omega",
          "σ": "sigma", "—": "-", "–": "-", "−": "-", "×": "x", "≥": ">=", "≤": "<=",
          "µ": "u", "°": " deg"}


def _comment(text) -> str:
    """``text`` safe inside a C block comment: printable ASCII but the backslash kept, the
    symbols of :data:`_ASCII` spelled out, anything else as ``<U+XXXX>``; ``*/``, ``/*``
    and trigraphs' ``??`` broken apart."""
    out = "".join(_ASCII[c] if c in _ASCII else c if " " <= c <= "~" and c != "\\"
                  else f"<U+{ord(c):04X}>" for c in str(text))
    while "*/" in out or "/*" in out or "??" in out:
        out = out.replace("*/", "* /").replace("/*", "/ *").replace("??", "? ?")
    return out


def _string(text) -> str:
    """``text`` as the body of a C string literal: printable ASCII kept, ``\\``, ``"`` and
    ``?`` escaped, ``*``, ``/`` (no comment marker even for a naive reader) and every other
    byte of its UTF-8 as a three-digit octal escape."""
    out = []
    for b in str(text).encode("utf-8"):
        c = chr(b)
        out.append("\\" + c if c in '\\"?' else c if 0x20 <= b < 0x7F and c not in "*/"
                   else f"\\{b:03o}")
    return "".join(out)


def schur_realisation(A: np.ndarray, B: np.ndarray, C: np.ndarray, reference=None):
    """``(QᵀAQ, QᵀB, CQ)`` with ``Q`` the orthogonal Schur vectors of ``reference`` (``A``
    when omitted): quasi upper-triangular ``QᵀAQ`` for ``reference = A``."""
    n = A.shape[-1]
    if n == 0:
        return A, B, C
    _, Q = sla.schur(A if reference is None else reference, output="real")
    return Q.T @ A @ Q, Q.T @ B, C @ Q


def _array(name: str, X: np.ndarray, ctype: str, suffix: str) -> str:
    digits = 17 if suffix == "" else 9  # round-trip precision of double / float
    vals = [f"{float(v):.{digits}e}{suffix}" for v in np.ravel(X)]
    if not vals:
        vals = [f"0.0{suffix}"]  # C forbids empty arrays; never read
    rows = [", ".join(vals[i:i + 4]) for i in range(0, len(vals), 4)]
    body = ",\n    ".join(rows)
    return f"static const {ctype} {name}[{max(X.size, 1)}] = {{\n    {body}\n}};\n"


def _header(p: str, ctype: str, n: int, ny: int, nu: int, ts: float, doc: str,
            var: str | None, name: str, holds: bool | None = None) -> str:
    P = p.upper()
    judged = "" if holds is None else (
        f"#define {P}_JUDGED_HOLDS {int(bool(holds))}   /* 1: the judged loop holds as it "
        "runs; 0: it does not (see above) */\n")
    step = (f"void {p}_step({p}_state *s, {ctype} {var}, const {ctype} y[{P}_NY], "
            f"{ctype} i[{P}_NU]);" if var else
            f"void {p}_step({p}_state *s, const {ctype} y[{P}_NY], {ctype} i[{P}_NU]);")
    return f"""/* {p}.h — generated by ambseal; do not edit.
{doc} */
#ifndef {P}_H
#define {P}_H

#define {P}_NX {n}   /* controller states */
#define {P}_NY {ny}   /* inputs: sensor displacements (m) */
#define {P}_NU {nu}   /* outputs: current references (A) */
#define {P}_TS {ts!r}   /* sample time (s) */
#define {P}_NAME "{_string(name)}"   /* the controller's name */
{judged}
typedef struct {{ {ctype} x[{P}_NX > 0 ? {P}_NX : 1]; }} {p}_state;

/* Set the controller state to zero (before the first sample, or after a fault). */
void {p}_reset({p}_state *s);
/* One sample: i = -(C x + D y), then x = A x + B y. */
{step}

#endif
"""


def _body(P: str, ctype: str, suffix: str, upper: bool) -> str:
    """The shared update; ``A``, ``B``, ``C``, ``D`` are row-major pointers."""
    j0 = "r > 0 ? r - 1 : 0" if upper else "0"
    return f"""    {ctype} xn[{P}_NX > 0 ? {P}_NX : 1];
    int r, c;
    for (r = 0; r < {P}_NU; ++r) {{
        {ctype} acc = 0.0{suffix};
        for (c = 0; c < {P}_NX; ++c) acc += C[r * {P}_NX + c] * s->x[c];
        for (c = 0; c < {P}_NY; ++c) acc += D[r * {P}_NY + c] * y[c];
        i[r] = -acc;
    }}
    for (r = 0; r < {P}_NX; ++r) {{
        {ctype} acc = 0.0{suffix};
        for (c = {j0}; c < {P}_NX; ++c) acc += A[r * {P}_NX + c] * s->x[c];
        for (c = 0; c < {P}_NY; ++c) acc += B[r * {P}_NY + c] * y[c];
        xn[r] = acc;
    }}
    for (r = 0; r < {P}_NX; ++r) s->x[r] = xn[r];
"""


def write_c(ctrl, out_dir, prefix: str = "ambseal_controller", precision: str = "double",
            verdict: dict | None = None) -> list[Path]:
    """Write ``<prefix>.h`` and ``<prefix>.c`` implementing ``ctrl`` (module docstring).

    Parameters
    ----------
    ctrl : DigitalController or ScheduledDigital
        The discrete controller as judged (its discretisation, delay and, scheduled, its
        table against the parameter); the C code's ``step`` gives the current references
        ``i = −K y`` (A) from the displacements ``y`` (m).
    out_dir : path
        Folder (created).
    prefix : str
        C identifier prefix and file name.
    precision : {"double", "float"}
        C floating-point type of the matrices and the state.
    verdict : dict, optional
        :func:`ambseal.export.controller_files.loop_verdict`: the header says in a comment
        whether the judged loop holds, where, and whether ``--allow-unstable`` kept it, and
        defines ``<PREFIX>_JUDGED_HOLDS`` 1 or 0 (a target can refuse to start on 0).

    Returns
    -------
    list of Path
        Header and source.

    Raises
    ------
    ConfigError
        Unknown precision or a prefix that is not a C identifier.
    """
    ctype, suf = _c_names(prefix, precision)
    p, P = prefix, prefix.upper()
    scheduled = isinstance(ctrl, ScheduledDigital)
    if scheduled:
        A, B, C, D = (np.asarray(X, float) for X in ctrl.discrete)
        mid = A[A.shape[0] // 2]
        parts = [schur_realisation(a, b, c, mid) for a, b, c in zip(A, B, C)]
        A, B, C = (np.stack([q[i] for q in parts]) for i in range(3))
        n, ny, nu = A.shape[1], D.shape[2], D.shape[1]
        var = "speed_rad_s" if ctrl.parameter == SPEED else "theta"
        name = str(ctrl.name)
        doc = (f"Scheduled controller {_comment(name)}: {A.shape[0]} table entries, "
               f"interpolation {_comment(ctrl.interpolation)}" + (
                   "." if var != "theta" else f"; theta = {_comment(ctrl.parameter)} (SI)."))
    else:
        d = ctrl.discrete
        A, B, C = schur_realisation(d.A, d.B, d.C)
        D, var = d.D, None
        n, (nu, ny) = A.shape[0], D.shape
        name = str(ctrl.continuous.name)
        doc = f"Controller {_comment(name)}."
    doc += (f"\nDiscretised by {_comment(ctrl.method)} at {float(ctrl.sample_rate_hz):g} Hz, "
            f"judged with {int(ctrl.delay_samples)} sample(s) of computation delay.\n"
            f"Inputs (m): {_comment(', '.join(ctrl.inputs))}.\n"
            f"Outputs (A): {_comment(', '.join(ctrl.outputs))}; i = -K y.")
    holds = None
    if verdict is not None:
        holds = verdict["loop_holds"]
        doc += (f"\nJudged loop: {_comment(verdict['verdict'])}" + (
            "\nExported with --allow-unstable." if verdict["allow_unstable"] else ""))
    h = _header(p, ctype, n, ny, nu, float(ctrl.Ts), doc, var, name, holds)
    src = [f"/* {p}.c — generated by ambseal; do not edit. */\n#include \"{p}.h\"\n\n"]
    src += [_array(f"{k}_", X, ctype, suf) for k, X in zip("ABCD", (A, B, C, D))]
    src.append(f"\nvoid {p}_reset({p}_state *s)\n{{\n    int r;\n"
               f"    for (r = 0; r < {P}_NX; ++r) s->x[r] = 0.0{suf};\n}}\n\n")
    if scheduled:
        W = np.asarray(ctrl.grid, float)
        src.append(_array("W_", W, ctype, suf))
        src.append(_scheduled_step(p, P, ctype, suf, W.size, var))
    else:
        src.append(f"void {p}_step({p}_state *s, const {ctype} y[{P}_NY], {ctype} i[{P}_NU])\n"
                   f"{{\n    const {ctype} *A = A_, *B = B_, *C = C_, *D = D_;\n"
                   + _body(P, ctype, suf, upper=True) + "}\n")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    return [write_text(out / f"{p}.h", h), write_text(out / f"{p}.c", "".join(src))]


def _c_names(prefix: str, precision: str) -> tuple[str, str]:
    """``(C type, literal suffix)`` of ``precision``, the prefix checked as a C
    identifier; ConfigError naming either."""
    if precision not in _PRECISION:
        raise ConfigError(f"precision={precision!r}: expected 'double' or 'float'")
    if not isinstance(prefix, str) or not _IDENTIFIER.fullmatch(prefix):
        raise ConfigError(f"prefix={prefix!r}: expected a C identifier "
                          "([A-Za-z_][A-Za-z0-9_]*)")
    return _PRECISION[precision]


def _scheduled_step(p: str, P: str, ctype: str, suf: str, nt: int, var: str) -> str:
    """The LPV step: find the table segment of θ (``var``), interpolate, update."""
    sizes = {"A": f"{P}_NX * {P}_NX", "B": f"{P}_NX * {P}_NY", "C": f"{P}_NU * {P}_NX",
             "D": f"{P}_NU * {P}_NY"}
    decl = "".join(f"    {ctype} {k}[({v}) > 0 ? ({v}) : 1];\n" for k, v in sizes.items())
    interp = "".join(
        f"    for (r = 0; r < {v}; ++r) {k}[r] = (1.0{suf} - t) * {k}_[j * ({v}) + r] "
        f"+ t * {k}_[(j + 1) * ({v}) + r];\n" for k, v in sizes.items())
    return f"""
/* {nt} table entries; {var} held at the ends of the table. */
void {p}_step({p}_state *s, {ctype} {var}, const {ctype} y[{P}_NY], {ctype} i[{P}_NU])
{{
{decl}    int j = 0, r;
    {ctype} t;
    if ({var} <= W_[0]) {{ j = 0; t = 0.0{suf}; }}
    else if ({var} >= W_[{nt - 1}]) {{ j = {max(nt - 2, 0)}; t = {1 if nt > 1 else 0}.0{suf}; }}
    else {{
        while ({var} > W_[j + 1]) ++j;
        t = ({var} - W_[j]) / (W_[j + 1] - W_[j]);
    }}
{interp}    {{
        int c;
{_body(P, ctype, suf, upper=False).replace("    int r, c;" + chr(10), "")}    }}
}}
"""


def write_notch_c(notch, out_dir, prefix: str = "ambseal_rejection",
                  precision: str = "double") -> list[Path]:
    """Write ``<prefix>.h`` and ``<prefix>.c`` implementing a discrete synchronous notch
    (:class:`~ambseal.machine.synchronous_notch.SynchronousNotch`; the convention of
    :mod:`ambseal.export.notch_files`).

    Every sample, with the measured speed, ``<prefix>_step(&s, speed_rad_s, y, q)`` gives
    the displacements ``q`` (m) the controller reads in place of ``y``:
    ``ambseal_mu_rejection_step(&n, speed_rad_s, y, q);`` then
    ``ambseal_mu_step(&s, q, i);``.

    Parameters
    ----------
    notch : SynchronousNotch
        The discrete notch as judged (``dt`` > 0).
    out_dir : path
        Folder (created).
    prefix : str
        C identifier prefix and file name.
    precision : {"double", "float"}
        C floating-point type of the table and the state.

    Returns
    -------
    list of Path
        Header and source.

    Raises
    ------
    ConfigError
        Unknown precision, a prefix that is not a C identifier, or a continuous notch.
    """
    ctype, suf = _c_names(prefix, precision)
    if not notch.dt > 0:
        raise ConfigError("a continuous notch does not run on a target (dt = 0)")
    p, P = prefix, prefix.upper()
    W = np.asarray(notch.speeds_rad_s, float)
    ny, nt = len(notch.inputs), W.size
    doc = (f"Synchronous notch (unbalance force rejection, Herzog et al. 1996) on "
           f"{_comment(', '.join(notch.inputs))} (m): q = y - a, then [a; b] rotated by "
           f"speed*Ts after adding eps*Ts*[T_re; T_im](speed)*q, eps = "
           f"{float(notch.rate_fraction)!r}*speed; off (q = y, state cleared) below "
           f"{float(notch.on_rad_s)!r} rad/s. Gains interpolated linearly in the speed between "
           f"{nt} table entries, held at its ends.")
    h = f"""/* {p}.h — generated by ambseal; do not edit.
{doc} */
#ifndef {P}_H
#define {P}_H

#define {P}_NY {ny}   /* inputs y and outputs q: sensor displacements (m) */
#define {P}_TS {float(notch.dt)!r}   /* sample time (s) */

typedef struct {{ {ctype} a[{P}_NY]; {ctype} b[{P}_NY]; }} {p}_state;

/* Set the notch state to zero (before the first sample, or after a fault). */
void {p}_reset({p}_state *s);
/* One sample at the measured speed (rad/s): q, what the controller reads in place of y. */
void {p}_step({p}_state *s, {ctype} speed_rad_s, const {ctype} y[{P}_NY], {ctype} q[{P}_NY]);

#endif
"""
    size = f"{P}_NY * {P}_NY"

    def nxt(table: str) -> str:  # the next entry's share (none in a one-entry table)
        return f" + t * {table}[(j + 1) * ({size}) + r]" if nt > 1 else ""

    src = [f"/* {p}.c — generated by ambseal; do not edit. */\n#include <math.h>\n"
           f"#include \"{p}.h\"\n\n",
           _array("W_", W, ctype, suf), _array("TR_", notch.gain_re, ctype, suf),
           _array("TI_", notch.gain_im, ctype, suf),
           f"""static const {ctype} ON_ = {float(notch.on_rad_s)!r}{suf};
static const {ctype} RATE_ = {float(notch.rate_fraction)!r}{suf};

void {p}_reset({p}_state *s)
{{
    int r;
    for (r = 0; r < {P}_NY; ++r) {{ s->a[r] = 0.0{suf}; s->b[r] = 0.0{suf}; }}
}}

void {p}_step({p}_state *s, {ctype} speed_rad_s, const {ctype} y[{P}_NY], {ctype} q[{P}_NY])
{{
    {ctype} tr[{size}], ti[{size}], t, w = speed_rad_s < 0 ? -speed_rad_s : speed_rad_s;
    {ctype} mu, c, sn;
    int j = 0, r, k;
    if (w < ON_) {{
        {p}_reset(s);
        for (r = 0; r < {P}_NY; ++r) q[r] = y[r];
        return;
    }}
    if (w <= W_[0]) {{ j = 0; t = 0.0{suf}; }}
    else if (w >= W_[{nt - 1}]) {{ j = {max(nt - 2, 0)}; t = {1 if nt > 1 else 0}.0{suf}; }}
    else {{
        while (w > W_[j + 1]) ++j;
        t = (w - W_[j]) / (W_[j + 1] - W_[j]);
    }}
    for (r = 0; r < {size}; ++r) {{
        tr[r] = (1.0{suf} - t) * TR_[j * ({size}) + r]{nxt("TR_")};
        ti[r] = (1.0{suf} - t) * TI_[j * ({size}) + r]{nxt("TI_")};
    }}
    for (r = 0; r < {P}_NY; ++r) q[r] = y[r] - s->a[r];
    mu = RATE_ * w * ({ctype}){P}_TS;
    c = ({ctype})cos((double)(w * ({ctype}){P}_TS));
    sn = ({ctype})sin((double)(w * ({ctype}){P}_TS));
    for (r = 0; r < {P}_NY; ++r) {{
        {ctype} u = s->a[r], v = s->b[r];
        for (k = 0; k < {P}_NY; ++k) {{
            u += mu * tr[r * {P}_NY + k] * q[k];
            v += mu * ti[r * {P}_NY + k] * q[k];
        }}
        s->a[r] = c * u - sn * v;
        s->b[r] = sn * u + c * v;
    }}
}}
"""]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    return [write_text(out / f"{p}.h", h), write_text(out / f"{p}.c", "".join(src))]
