# Loads the native module (hedge._native) and keeps the reason when it cannot be loaded, so
# the panel can show it instead of failing silently (e.g. a module built for another Python).
import sys

try:
    from . import _native as native
    load_error = None
    Error = native.Error
    Cancelled = native.Cancelled
except ImportError as e:  # wrong Python version, missing file, missing library
    native = None
    load_error = (f"hedge's native module could not be loaded into Blender's Python "
                  f"{sys.version_info.major}.{sys.version_info.minor}: {e}")

    class Error(RuntimeError):
        pass

    class Cancelled(Error):
        pass


def require_native():
    if native is None:
        raise Error(load_error)
    return native
