# The add-on zip installs and enables in blender -b; the native module exposes the catalogue;
# every catalogue operation is an operator mesh.hedge_<id> with its parameters as properties.
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402
from blender_test import add_primitive, clear_scene, install_addon, run_tests  # noqa: E402
import unittest  # noqa: E402

hedge = install_addon()


class AddonTest(unittest.TestCase):
    def test_installed_in_user_scripts(self):
        path = os.path.join(bpy.utils.user_resource('SCRIPTS'), "addons", "hedge")
        self.assertTrue(os.path.isdir(path), path)
        self.assertTrue(any(f.startswith("_native") and f.endswith(".so") for f in os.listdir(path)))
        self.assertIsNotNone(hedge.native.native, hedge.native.load_error)

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
        addon_utils.disable("hedge")
        self.assertNotIn("hedge_decimate", dir(bpy.ops.mesh))
        self.assertFalse(hasattr(bpy.types, "VIEW3D_PT_hedge"))
        addon_utils.enable("hedge", default_set=True, handle_error=None)
        self.assertIn("hedge_decimate", dir(bpy.ops.mesh))

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
