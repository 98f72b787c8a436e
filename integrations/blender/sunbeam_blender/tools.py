"""Finding and running the Sunbeam command-line tools.

The add-on never reimplements a pipeline step: every step is one of the tools, run as a
child process. This module is the one place that knows where the tools are (the add-on
preference, then PATH, then the project's target/release beside this source tree), how a
failure is turned into the tool's own message, and how a cancelled render kills the child.
"""

import os
import shutil
import subprocess
import threading
import time
from pathlib import Path

# integrations/blender/sunbeam_blender/tools.py -> the repository root, when the add-on is
# used straight from a clone (the tools' release build is then in target/release).
_PROJECT_RELEASE = Path(__file__).resolve().parents[3] / "target" / "release"


class SunbeamError(Exception):
    """A failure to show the user as a Blender error report, message ready to read."""


class Cancelled(Exception):
    """The user stopped the render; the child process has been killed."""


def preferences_folder():
    """The binaries folder set in the add-on preferences, or '' when unset."""
    import bpy

    addon = bpy.context.preferences.addons.get(__package__)
    return bpy.path.abspath(addon.preferences.binaries_folder) if addon else ""


def find_tool(name):
    """Path of tool `name`: the preference's folder if set, else PATH, else target/release."""
    folder = preferences_folder()
    if folder:
        path = Path(folder) / name
        if path.is_file() and os.access(path, os.X_OK):
            return str(path)
        raise SunbeamError(
            f"{name} not found in the binaries folder '{folder}' "
            "(Preferences > Add-ons > Sunbeam > Binaries Folder)")
    found = shutil.which(name)
    if found:
        return found
    path = _PROJECT_RELEASE / name
    if path.is_file() and os.access(path, os.X_OK):
        return str(path)
    raise SunbeamError(
        f"{name} not found on PATH nor in {_PROJECT_RELEASE} "
        "(set Preferences > Add-ons > Sunbeam > Binaries Folder)")


def _tool_message(name, stderr):
    """The tool's own error line (its last `error:` line), else its last line of stderr."""
    lines = [line.strip() for line in stderr.splitlines() if line.strip()]
    for line in reversed(lines):
        if "error:" in line:
            return line
    return lines[-1] if lines else f"{name} failed without a message"


def run(name, args, cancelled=lambda: False, poll_s=0.1):
    """Run tool `name` with `args`; return its stdout.

    `cancelled` is polled while the child runs; when it returns True the child is killed
    and Cancelled is raised. A non-zero exit raises SunbeamError with the tool's message.
    """
    exe = find_tool(name)
    out, err = [], []
    with subprocess.Popen([exe, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          stdin=subprocess.DEVNULL, text=True) as proc:
        readers = [threading.Thread(target=lambda s=s, b=b: b.append(s.read()), daemon=True)
                   for s, b in ((proc.stdout, out), (proc.stderr, err))]
        for reader in readers:
            reader.start()
        while proc.poll() is None:
            if cancelled():
                proc.kill()
                proc.wait()
                raise Cancelled()
            time.sleep(poll_s)
        for reader in readers:
            reader.join()
    if proc.returncode != 0:
        raise SunbeamError(_tool_message(name, "".join(err)))
    return "".join(out)
