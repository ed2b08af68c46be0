# The package installs and enables in blender -b as a user of this Blender installs it (the
# legacy zip before 4.2, the extension after); the native module for this Python loads and
# exposes the catalogue; every catalogue operation is an operator mesh.hedge_<id> with its
# parameters as properties; `import hedge` reaches the batch API in every version.
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402
from blender_test import add_primitive, clear_scene, hedge_install, install_addon, run_tests  # noqa: E402
import unittest  # noqa: E402

hedge = install_addon()


class AddonTest(unittest.TestCase):
    def test_installed_in_user_folder(self):
        path = hedge_install.installed_folder()
        self.assertTrue(os.path.isdir(path), path)
        files = os.listdir(path)
        # One module per Python built for; this Blender's among them, and loaded.
        modules = [f for f in files if f.startswith("_native.cpython-") and f.endswith(".so")]
        tag = f"cpython-{sys.version_info.major}{sys.version_info.minor}-"
        self.assertTrue(any(tag in f for f in modules), modules)
        self.assertIsNotNone(hedge.native.native, hedge.native.load_error)
        self.assertIn(tag, hedge.native.native.__file__)
        self.assertEqual("blender_manifest.toml" in files, hedge_install.EXTENSIONS)
        self.assertEqual(hedge.__name__, hedge_install.MODULE)
        self.assertTrue(os.path.samefile(os.path.dirname(hedge.__file__), path))

    def test_import_hedge_is_the_package(self):
        import hedge as by_name
        from hedge import api
        self.assertIs(by_name, sys.modules[hedge_install.MODULE])
        self.assertIs(api, sys.modules[hedge_install.MODULE + ".api"])
        self.assertIs(by_name.run, api.run)

    def test_operator_per_operation(self):
        ids = [op["id"] for op in hedge.catalogue()]
        self.assertIn("decimate", ids)
        self.assertIn("report", ids)
        for op in hedge.catalogue():
            rna = getattr(bpy.ops.mesh, f"hedge_{op['id']}").get_rna_type()
            self.assertEqual(rna.name, op["title"])
            props = {p.identifier: p for p in rna.properties if p.identifier != "rna_type"}
            self.assertEqual(set(props), {p["id"] for p in op["params"]}, op["id"])
            for p in op["params"]:
                prop = props[p["id"]]
                if p["type"] == "enum":
                    self.assertEqual([i.identifier for i in prop.enum_items], p["choices"])
                    self.assertEqual(prop.default, p["default"])
                elif p["type"] == "float":
                    self.assertAlmostEqual(prop.default, p["default"], places=5)
                    self.assertAlmostEqual(prop.hard_min, max(p["min"], -3e38), delta=abs(p["min"]) * 1e-6 + 1e-9)
                else:
                    self.assertEqual(prop.default, p["default"])
                self.assertIn(p["help"][:20], prop.description)

    def test_panel_and_menus(self):
        self.assertTrue(hasattr(bpy.types, "VIEW3D_PT_hedge"))
        self.assertEqual(bpy.types.VIEW3D_PT_hedge.bl_category, "Hedge")
        self.assertEqual(bpy.types.VIEW3D_PT_hedge.bl_region_type, 'UI')
        self.assertTrue(hasattr(bpy.types, "VIEW3D_MT_hedge"))
        for menu in ("VIEW3D_MT_object", "VIEW3D_MT_edit_mesh"):
            draw_funcs = getattr(bpy.types, menu).draw._draw_funcs
            self.assertIn(hedge.panel.menu_entry, draw_funcs, menu)

    def test_disable_enable(self):
        import addon_utils
        addon_utils.disable(hedge_install.MODULE)
        self.assertNotIn("hedge_decimate", dir(bpy.ops.mesh))
        self.assertFalse(hasattr(bpy.types, "VIEW3D_PT_hedge"))
        if hedge_install.EXTENSIONS:
            self.assertNotIn("hedge", sys.modules)  # the alias goes with the extension
        hedge_install.enable()
        self.assertIn("hedge_decimate", dir(bpy.ops.mesh))
        import hedge as again
        self.assertIs(again, sys.modules[hedge_install.MODULE])

    def test_decimate_sphere(self):
        clear_scene()
        obj = add_primitive("uv_sphere", segments=64, ring_count=32)
        self.assertEqual(bpy.ops.mesh.hedge_triangulate(), {'FINISHED'})
        before = len(obj.data.polygons)
        self.assertEqual(before, 2 * 64 * 31)
        self.assertEqual(bpy.ops.mesh.hedge_decimate(target_ratio=0.25), {'FINISHED'})
        after = len(obj.data.polygons)
        self.assertEqual(after, before // 4)  # the target face count is reached exactly
        self.assertIn("seconds", hedge.api.last_reports["decimate"])


run_tests(AddonTest)
