# A native module that cannot load still lets the add-on enable, and the panel says why
# instead of failing silently; no operator is registered. Two ways: the module for this Python
# is not a shared library, and the package has no module for this Python (one built for
# others only: the reason names the Pythons it has).
import os
import sys
import zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import addon_utils  # noqa: E402
import bpy  # noqa: E402
import unittest  # noqa: E402
from blender_test import ARGS, hedge_install, install_addon, run_tests  # noqa: E402

THIS_PYTHON = f"{sys.version_info.major}.{sys.version_info.minor}"
THIS_MODULE = f"_native.cpython-{sys.version_info.major}{sys.version_info.minor}-"


def rewritten(name, change):
    """A copy of the package zip with change(basename, data) -> data or None (left out)."""
    path = os.path.join(ARGS.out, name)
    with zipfile.ZipFile(ARGS.zip) as src, zipfile.ZipFile(path, "w") as dst:
        for item in src.infolist():
            data = change(os.path.basename(item.filename), src.read(item))
            if data is not None:
                dst.writestr(item, data)
    return path


class BrokenNativeTest(unittest.TestCase):
    def check_refused(self, zip_path):
        # Each case afresh: the package of the case before disabled and forgotten.
        addon_utils.disable(hedge_install.MODULE)
        for name in [n for n in sys.modules if n == hedge_install.MODULE or n.startswith(hedge_install.MODULE + ".")]:
            del sys.modules[name]
        hedge = install_addon(zip_path)
        self.assertIsNone(hedge.native.native)
        self.assertIn("could not be loaded", hedge.native.load_error)
        self.assertIn(f"Python {THIS_PYTHON}", hedge.native.load_error)
        self.assertTrue(hasattr(bpy.types, "VIEW3D_PT_hedge"))
        self.assertNotIn("hedge_decimate", dir(bpy.ops.mesh))
        with self.assertRaises(hedge.Error):
            hedge.run(None, "decimate")
        print("\nreason shown:", hedge.native.load_error)
        return hedge.native.load_error

    def test_not_a_library(self):
        self.check_refused(rewritten("hedge_broken.zip", lambda name, data: b"not a shared library"
                                     if name.startswith(THIS_MODULE) else data))

    def test_no_module_for_this_python(self):
        others = []

        def drop(name, data):
            if name.startswith(THIS_MODULE):
                return None
            if name.startswith("_native.cpython-"):
                others.append(name)
            return data
        reason = self.check_refused(rewritten("hedge_other_pythons.zip", drop))
        versions = sorted((name.split("-")[1] for name in others), key=int)
        self.assertIn("this package has modules for Python " + (", ".join(v[0] + "." + v[1:] for v in versions)
                                                                  or "none"), reason)


run_tests(BrokenNativeTest)
