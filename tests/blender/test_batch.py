# The batch API as scripts use it: `blender -b file.blend --python-exit-code 1 --python job.py`
# with `import hedge; hedge.run(obj, ...)`: exit 0 and the result saved on success, a
# non-zero exit with the reason on failure. Runs blender itself (bpy.app.binary_path).
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402
import unittest  # noqa: E402
from blender_test import ARGS, add_primitive, clear_scene, install_addon, run_tests  # noqa: E402

hedge = install_addon()
OUT = ARGS.out or bpy.app.tempdir

JOB = """
import bpy, hedge, json, sys
obj = bpy.data.objects["Suzanne"]
report = hedge.run(obj, sys.argv[-2], **json.loads(sys.argv[-1]))
print("REPORT", json.dumps(report))
bpy.ops.wm.save_as_mainfile(filepath=bpy.data.filepath.replace(".blend", "_out.blend"))
"""


def blender(*args):
    # The add-on is enabled in the saved preferences of this test's private HOME.
    return subprocess.run([bpy.app.binary_path, "-b", *args], capture_output=True, text=True, timeout=300)


class BatchTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        bpy.context.preferences.use_preferences_save = True
        bpy.ops.wm.save_userpref()  # hedge enabled for the child blender processes
        clear_scene()
        add_primitive("monkey")
        cls.blend = os.path.join(OUT, "suzanne.blend")
        bpy.ops.wm.save_as_mainfile(filepath=cls.blend)
        cls.job = os.path.join(OUT, "job.py")
        with open(cls.job, "w") as f:
            f.write(JOB)

    def run_job(self, op, params):
        return blender(self.blend, "--python-exit-code", "1", "--python", self.job, "--", op, json.dumps(params))

    def test_success(self):
        done = self.run_job("decimate", {"target_faces": 200})
        self.assertEqual(done.returncode, 0, done.stdout[-2000:] + done.stderr[-2000:])
        line = next(l for l in done.stdout.splitlines() if l.startswith("REPORT "))
        report = json.loads(line[len("REPORT "):])
        self.assertEqual(report["faces_after"], 200)
        check = blender(self.blend.replace(".blend", "_out.blend"), "--python-expr",
                        "import bpy; print('FACES', len(bpy.data.objects['Suzanne'].data.polygons))")
        self.assertIn("FACES 200", check.stdout)

    def test_failure_exit_code(self):
        out = self.blend.replace(".blend", "_out.blend")
        if os.path.exists(out):
            os.remove(out)
        done = self.run_job("decimate", {"target_ratio": 7})
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("target_ratio must be", done.stdout + done.stderr)
        done = self.run_job("no_such_operation", {})
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("unknown operation", done.stdout + done.stderr)
        self.assertFalse(os.path.exists(out), "the failed job went on to save")


run_tests(BatchTest)
