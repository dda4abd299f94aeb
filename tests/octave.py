"""GNU Octave with its control package, where the machine has it (the .mat export's and the
manual's MATLAB blocks are run there)."""

import functools
import shutil
import subprocess


@functools.cache
def octave_cli() -> str | None:
    """The path of octave-cli if it loads the control package, else None (checked once)."""
    exe = shutil.which("octave-cli")
    if exe is None:
        return None
    r = subprocess.run([exe, "--no-gui", "-q", "--eval", "pkg load control; disp(4242)"],
                       capture_output=True, text=True, timeout=120)
    return exe if r.returncode == 0 and "4242" in r.stdout else None
