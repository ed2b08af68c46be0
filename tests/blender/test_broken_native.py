# A native module that cannot load (here: not a shared library; in practice one built for
# another Python) still lets the add-on enable, and the panel says why instead of failing
# silently; no operator is registered.
import os
import sys
import zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import addon_utils  # noqa: E402
import bpy  # noqa: E402
import unittest  # noqa: E402
from blender_test import ARGS, run_tests  # noqa: E402


class BrokenNativeTest(unittest.TestCase):
    def test_reason_shown(self):
        broken = os.path.join(ARGS.out, "hedge_broken.zip")
        with zipfile.ZipFile(ARGS.zip) as src, zipfile.ZipFile(broken, "w") as dst:
            for item in src.infolist():
                data = src.read(item)
                if item.filename.startswith("hedge/_native"):
                    data = b"not a shared library"
                dst.writestr(item, data)
        bpy.ops.preferences.addon_install(filepath=broken, overwrite=True)
        addon_utils.modules_refresh()
        self.assertIsNotNone(addon_utils.enable("hedge", default_set=True, handle_error=None))
        import hedge
        self.assertIsNone(hedge.native.native)
        self.assertIn("could not be loaded", hedge.native.load_error)
        self.assertIn("3.11", hedge.native.load_error)
        self.assertTrue(hasattr(bpy.types, "VIEW3D_PT_hedge"))
        self.assertNotIn("hedge_decimate", dir(bpy.ops.mesh))
        with self.assertRaises(hedge.Error):
            hedge.run(None, "decimate")
        print("\nreason shown:", hedge.native.load_error)


run_tests(BrokenNativeTest)
