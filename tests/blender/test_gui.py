# GUI smoke test under Xvfb: Blender starts with the add-on enabled, the Hedge tab of the 3D
# View sidebar is found (3.4 has no API to choose a tab: simulated clicks walk the tab strip
# until the panel draws), an operator runs interactively (modal, with progress) and Esc
# cancels a long one leaving the mesh as it was, shape keys follow an interactive run and a key
# renamed during one is refused; screenshots are saved with the test output.
#   xvfb-run -a -s "-screen 0 1600x1000x24" blender --factory-startup --enable-event-simulate \
#            --python test_gui.py -- --zip ZIP --out DIR
import os
import shutil
import subprocess
import sys
import time
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402
import numpy as np  # noqa: E402
from blender_test import ARGS, install_addon  # noqa: E402

hedge = install_addon()
from hedge import operators, panel  # noqa: E402

log_lines = []


def log(text):
    print("[gui test]", text, flush=True)
    log_lines.append(text)


def finish(ok):
    with open(os.path.join(ARGS.out, "gui_test.log"), "w") as f:
        f.write("\n".join(log_lines) + "\n" + ("PASSED" if ok else "FAILED") + "\n")
    print("[gui test]", "PASSED" if ok else "FAILED", flush=True)
    sys.stdout.flush()
    os._exit(0 if ok else 1)


# The panel tells when it draws.
drawn = {"time": 0.0}
original_draw = panel.VIEW3D_PT_hedge.draw


def tracking_draw(self, context):
    drawn["time"] = time.monotonic()
    original_draw(self, context)


panel.VIEW3D_PT_hedge.draw = tracking_draw


def view3d():
    win = bpy.context.window_manager.windows[0]
    for area in win.screen.areas:
        if area.type == 'VIEW_3D':
            return win, area
    raise RuntimeError("no 3D View")


def region(area, kind):
    return next(r for r in area.regions if r.type == kind)


def screenshot(name):
    """The X server's own pixels (imagemagick's `import`; under Xvfb bpy's screenshot is all
    black in 4.3 and 5.2), or bpy's where there is no `import`. A blank picture fails."""
    path = os.path.join(ARGS.out, name)
    if shutil.which("import"):
        subprocess.run(["import", "-window", "root", path], check=True, timeout=60)
    else:
        win, area = view3d()
        with bpy.context.temp_override(window=win, area=area):
            bpy.ops.screen.screenshot(filepath=path)
    image = bpy.data.images.load(path)
    try:
        pixels = np.empty(len(image.pixels), np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    spread = float(pixels.reshape(-1, 4)[:, :3].std())
    log(f"screenshot {path} ({os.path.getsize(path)} bytes, colour spread {spread:.3f})")
    assert spread > 0.02, f"{name} is blank"


def click(win, x, y):
    win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x, y=y)
    win.event_simulate(type='LEFTMOUSE', value='PRESS', x=x, y=y)
    win.event_simulate(type='LEFTMOUSE', value='RELEASE', x=x, y=y)


def steps():
    """The test as a generator: each yield lets Blender run (redraw, handle events) for the
    given seconds."""
    win, area = view3d()
    space = area.spaces.active
    space.show_region_ui = True
    obj = bpy.context.active_object  # the default cube
    bpy.ops.object.select_all(action='DESELECT')
    bpy.ops.mesh.primitive_monkey_add(location=(0, 0, 0))
    obj = bpy.context.active_object
    bpy.data.objects["Cube"].hide_set(True)
    with bpy.context.temp_override(window=win, area=area):
        bpy.ops.ed.undo_push(message="Suzanne")  # what a user's own edit would leave
    yield 1.0
    ui = region(area, 'UI')
    log(f"sidebar region x={ui.x} y={ui.y} {ui.width}x{ui.height}")
    # The tab strip is the right edge of the sidebar; walk it from the top.
    found = False
    x = ui.x + ui.width - 10
    started = time.monotonic()
    for y in range(ui.y + ui.height - 15, ui.y + 20, -12):
        before = drawn["time"]
        click(win, x, y)
        yield 0.3
        area.tag_redraw()
        yield 0.3
        if drawn["time"] > before:
            log(f"Hedge tab found at ({x}, {y}) in {time.monotonic() - started:.1f} s")
            found = True
            break
    if not found:
        screenshot("gui_no_tab.png")
        raise AssertionError("the Hedge sidebar panel never drew")
    # Move the mouse off the strip so no tooltip covers the panel.
    win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=area.x + area.width // 3, y=area.y + area.height // 2)
    yield 1.0
    # Mesh Report, interactively: its figures appear in the panel.
    with bpy.context.temp_override(window=win, area=area, region=region(area, 'WINDOW')):
        bpy.ops.mesh.hedge_report('INVOKE_DEFAULT')
    for _ in range(50):
        yield 0.2
        if not operators.running:
            break
    report = hedge.api.last_reports.get("report:" + obj.name)
    log(f"Mesh Report: {report and report['faces']} faces, {report and report['boundary_loops']} holes")
    assert report and report["faces"] == 500, "Mesh Report did not run"
    area.tag_redraw()
    yield 1.0
    screenshot("gui_hedge_panel.png")

    # An interactive run: the modal operator on a worker thread.
    faces = len(obj.data.polygons)
    with bpy.context.temp_override(window=win, area=area, region=region(area, 'WINDOW')):
        result = bpy.ops.mesh.hedge_subdivide('INVOKE_DEFAULT', scheme='catmull_clark', iterations=2)
    log(f"subdivide invoked: {result}")
    for _ in range(100):
        yield 0.2
        if len(obj.data.polygons) != faces:
            break
    log(f"faces {faces} -> {len(obj.data.polygons)}")
    assert len(obj.data.polygons) > faces, "the interactive run did not change the mesh"
    area.tag_redraw()
    yield 1.0
    screenshot("gui_after_subdivide.png")
    # Undo and redo in the real window: the modal run pushed one undo step.
    name = obj.name
    with bpy.context.temp_override(window=win, area=area):
        bpy.ops.ed.undo()
    yield 0.5
    obj = bpy.data.objects[name]
    log(f"after undo: {len(obj.data.polygons)} faces")
    assert len(obj.data.polygons) == faces, "undo did not restore the mesh"
    with bpy.context.temp_override(window=win, area=area):
        bpy.ops.ed.redo()
    yield 0.5
    obj = bpy.data.objects[name]
    log(f"after redo: {len(obj.data.polygons)} faces")
    assert len(obj.data.polygons) > faces, "redo did not bring the result back"

    # Esc cancels a long run and leaves the mesh as it was.
    co_before = np.empty(len(obj.data.vertices) * 3, np.float32)
    obj.data.vertices.foreach_get("co", co_before)
    n_before = len(obj.data.polygons)
    with bpy.context.temp_override(window=win, area=area, region=region(area, 'WINDOW')):
        bpy.ops.mesh.hedge_remesh('INVOKE_DEFAULT', target_edge_length=0.01, iterations=100)
    yield 1.0
    assert "remesh" in operators.running, "the remesh finished before Esc"
    pressed = time.monotonic()
    win.event_simulate(type='ESC', value='PRESS', x=area.x + 100, y=area.y + 100)
    win.event_simulate(type='ESC', value='RELEASE', x=area.x + 100, y=area.y + 100)
    for _ in range(300):
        yield 0.2
        if not operators.running:
            break
    log(f"Esc returned control in {time.monotonic() - pressed:.1f} s: {hedge.api.last_errors.get('remesh')}")
    for _ in range(300):
        if not operators.abandoned:
            break
        operators.reap_abandoned()
        yield 0.2
    log(f"the worker stopped {time.monotonic() - pressed:.1f} s after Esc")
    assert "cancelled" in hedge.api.last_errors.get("remesh", ""), "the remesh was not cancelled"
    co_after = np.empty(len(obj.data.vertices) * 3, np.float32)
    obj.data.vertices.foreach_get("co", co_after)
    log(f"after Esc: {len(obj.data.polygons)} faces (before {n_before})")
    assert len(obj.data.polygons) == n_before and np.array_equal(co_before, co_after), "Esc did not leave the mesh"
    screenshot("gui_after_cancel.png")

    # Shape keys through the interactive run; a key renamed while a run works is refused when
    # it ends (the key blocks would not match), the mesh unchanged.
    obj.hide_set(True)
    bpy.ops.mesh.primitive_uv_sphere_add(location=(0, 0, 0))
    sphere = bpy.context.active_object
    sphere.shape_key_add(name="Basis")
    dent = sphere.shape_key_add(name="Dent", from_mix=False)
    co = np.empty(len(sphere.data.vertices) * 3, np.float32)
    dent.data.foreach_get("co", co)
    dent.data.foreach_set("co", co * 0.9)
    sphere_faces = len(sphere.data.polygons)
    with bpy.context.temp_override(window=win, area=area, region=region(area, 'WINDOW')):
        bpy.ops.mesh.hedge_decimate('INVOKE_DEFAULT', target_ratio=0.25)
    for _ in range(100):
        yield 0.2
        if not operators.running:
            break
    keys = sphere.data.shape_keys.key_blocks
    log(f"keyed decimate: {len(sphere.data.vertices)} vertices, keys {[(k.name, len(k.data)) for k in keys]}")
    assert len(sphere.data.polygons) < sphere_faces / 2 and all(len(k.data) == len(sphere.data.vertices) for k in keys)
    vertices = len(sphere.data.vertices)
    with bpy.context.temp_override(window=win, area=area, region=region(area, 'WINDOW')):
        bpy.ops.mesh.hedge_remesh('INVOKE_DEFAULT', target_edge_length=0.01, iterations=20)
    yield 0.2
    assert "remesh" in operators.running, "the keyed remesh finished at once"
    keys["Dent"].name = "Renamed"
    for _ in range(600):
        yield 0.2
        if not operators.running:
            break
    log(f"key renamed during the run: {hedge.api.last_errors.get('remesh')}")
    assert "shape keys changed" in hedge.api.last_errors.get("remesh", ""), "the renamed key was not noticed"
    assert len(sphere.data.vertices) == vertices and len(keys["Renamed"].data) == vertices


def driver():
    generator = steps()

    def tick():
        try:
            return next(generator)
        except StopIteration:
            finish(True)
        except Exception:
            log(traceback.format_exc())
            finish(False)
        return None
    return tick


bpy.app.timers.register(driver(), first_interval=2.0)
# A watchdog: fail rather than hang.
bpy.app.timers.register(lambda: (log("timeout"), finish(False)), first_interval=300.0)
