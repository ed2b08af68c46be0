# Loads the native module (hedge._native) and keeps the reason when it cannot be loaded, so
# the panel can show it instead of failing silently (e.g. no module built for this Python).
# The package carries one module per Python it was built for, _native.cpython-3XY-<platform>.so;
# Python imports the one whose suffix it has.
import importlib.machinery
import os
import sys

try:
    from . import _native as native
    load_error = None
    Error = native.Error
    Cancelled = native.Cancelled
except ImportError as e:  # no module for this Python, a broken file, a missing library
    native = None
    _here = os.path.dirname(os.path.abspath(__file__))
    _built = sorted({f.split("-")[1] for f in os.listdir(_here) if f.startswith("_native.cpython-")}, key=int)
    _python = f"{sys.version_info.major}.{sys.version_info.minor}"
    _has = f"this package has modules for Python {', '.join(v[0] + '.' + v[1:] for v in _built) or 'none'}"
    if not any(os.path.exists(os.path.join(_here, "_native" + s)) for s in importlib.machinery.EXTENSION_SUFFIXES):
        load_error = f"hedge's native module could not be loaded into Blender's Python {_python}: {_has}"
    else:
        load_error = f"hedge's native module could not be loaded into Blender's Python {_python}: {e} ({_has})"

    class Error(RuntimeError):
        pass

    class Cancelled(Error):
        pass


def require_native():
    if native is None:
        raise Error(load_error)
    return native
