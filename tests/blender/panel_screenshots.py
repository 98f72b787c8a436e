"""Screenshots of the add-on's panels for docs/BLENDER.md (`make blender-panels-img`).

Blender as a Python module (the tests' `bpy`) always runs in background mode, where the
screenshot operators refuse to run, so this script runs in Blender's own executable with a
window (a virtual display: tests/blender/panel_screenshots.sh starts it under xvfb-run):

    blender --factory-startup --python tests/blender/panel_screenshots.py -- OUT_DIR

It enables the add-on from integrations/blender, builds a scene (a UV sphere with a Sunbeam
material, render engine Sunbeam), then, from timers so that the window has drawn, takes
`screen.screenshot_area` of the Properties editor on the Render, Material and Object tabs and
a `screen.screenshot` of the window with File > Import's menu open, crops them (the editor
down to its last panel; the menu by the pixels that changed when it opened) and writes
OUT_DIR/blender-panel-*.png as 8-bit RGB PNGs.

Then it checks the engine's viewport (rendered shading, `sunbeam-play`): the sphere gets a real
pack (a small synthetic one that `sunbeam-import` + `sunbeam-pack --response` write into a
temporary folder while the panels are taken), the factory scene's lamp becomes a sun, the 3D
Viewport is maximised (no overlays, no gizmos) and switched to 'RENDERED'; once the engine has
drawn its frame (view_draw made a texture of a finished frame, no `sunbeam-play` runs) it takes
`screen.screenshot_area` of the viewport, fails when the engine reported an error or when the
sphere's disc (projected by the view) does not differ clearly from the viewport's background,
and writes OUT_DIR/blender-viewport-rendered.png (cut to a square around the sphere). Last, F12
in the UI: `render.render` invoked (the engine in Blender's render job thread), failing unless
the job completes with no error report and the Render Result's sphere is lit. Then it quits;
any failure exits non-zero.
"""

import os
import shutil
import struct
import subprocess
import sys
import tempfile
import threading
import time
import traceback
import zlib
from array import array
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parents[2]
ADDON_DIR = ROOT / "integrations" / "blender"
ADDON = "sunbeam_blender"
SETTLE_S = 1.5  # seconds for the window to redraw after a change, before a screenshot
HIGHLIGHT_TRIES = 6  # pointer moves onto the import menu's last entry before giving up
VIEWPORT_TIMEOUT_S = 120  # for the engine's first viewport frame
VIEWPORT_PNG = "blender-viewport-rendered.png"

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if len(argv) != 1:
    print("usage: blender --factory-startup --python panel_screenshots.py -- OUT_DIR", file=sys.stderr)
    sys.exit(2)
OUT = Path(argv[0]).resolve()
TMP = Path(tempfile.mkdtemp(prefix="sunbeam-panels-"))
failed = []


def fail(msg):
    print(f"panel_screenshots: {msg}", file=sys.stderr)
    failed.append(msg)


def quit_blender():
    code = 1 if failed else 0
    # A sunbeam-play the viewport still runs would outlive Blender: have the add-on kill it.
    PLAY_RUNS["quit"] = True
    t = time.monotonic()
    while PLAY_RUNS["running"] and time.monotonic() - t < 10:
        time.sleep(0.1)
    shutil.rmtree(TMP, ignore_errors=True)
    # wm.quit_blender would exit 0 whatever happened; os._exit keeps the status.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


# ---- images: read a screenshot, crop, write a small PNG (Blender's Python has no PIL) ----

def read_png(path):
    """(width, height, rows): rows top to bottom, each a bytes object of RGB."""
    img = bpy.data.images.load(str(path))
    w, h = img.size
    px = array("f", bytes(4 * 4 * w * h))
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    b = bytes(min(255, int(v * 255.0 + 0.5)) for v in px)
    rows = []
    for y in range(h - 1, -1, -1):  # Blender's pixels start at the bottom row
        row = b[y * w * 4:(y + 1) * w * 4]
        rgb = bytearray(3 * w)
        rgb[0::3], rgb[1::3], rgb[2::3] = row[0::4], row[1::4], row[2::4]
        rows.append(bytes(rgb))
    return w, h, rows


def write_png(path, rows):
    """8-bit RGB PNG, each row 'Up'-filtered (flat UI colours then compress well)."""
    h, w = len(rows), len(rows[0]) // 3
    raw = bytearray()
    prev = bytes(3 * w)
    for row in rows:
        raw.append(2)
        raw += bytes((a - b) & 0xFF for a, b in zip(row, prev))
        prev = row

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b""))
    Path(path).write_bytes(png)
    print(f"panel_screenshots: wrote {path} ({w} x {h}, {len(png) // 1024} KB)")


def crop(rows, x0, y0, x1, y1):
    return [r[3 * x0:3 * x1] for r in rows[y0:y1]]


def trim_bottom(rows, margin=6):
    """Drop the rows at the bottom where the panels' column is one colour (the editor's
    background, its border), keeping `margin` of them."""
    w = len(rows[0]) // 3
    x0, x1 = 40, w - 20  # not the tabs at the left, nor the scroll bar at the right
    y = len(rows)
    while y > 1 and rows[y - 1][3 * x0:3 * x1] == rows[y - 1][3 * x0:3 * x0 + 3] * (x1 - x0):
        y -= 1
    return rows[:min(len(rows), y + margin)]


def changed_box(a, b):
    """The bounding box (x0, y0, x1, y1) of the pixels that differ between two screenshots."""
    ys = [y for y in range(len(a)) if a[y] != b[y]]
    if not ys:
        return None
    x0, x1 = len(a[0]), 0
    for y in ys:
        ra, rb = a[y], b[y]
        i = next(i for i in range(len(ra)) if ra[i] != rb[i])
        j = next(j for j in range(len(ra) - 1, -1, -1) if ra[j] != rb[j])
        x0, x1 = min(x0, i // 3), max(x1, j // 3 + 1)
    return x0, ys[0], x1, ys[-1] + 1


# ---- the scene and the window ----

PACK = {"path": None, "error": None, "thread": None}  # the viewport's pack, made in a thread
ENGINE_ERRORS = []  # what the engine's viewport export and sunbeam-play runs raised
PLAY_RUNS = {"started": 0, "running": 0, "finished": 0, "quit": False, "shown": 0}


def make_pack():
    """Start writing a small synthetic pack (as tests/blender/test_addon.py makes its own) with
    the tools the add-on finds, in a thread: the panels' screenshots go on meanwhile."""
    from sunbeam_blender import tools
    exes = [tools.find_tool(name) for name in ("sunbeam-import", "sunbeam-pack")]
    folder = TMP / "pack"
    folder.mkdir()
    cmds = [[exes[0], "synthetic:elaphe", "--synthetic-size", "32", "-o", str(folder / "skin.exr"), "-q"],
            [exes[1], str(folder / "skin.exr"), "-o", str(folder / "skin.ktx2"), "--response", "-q"]]

    def work():
        for cmd in cmds:
            out = subprocess.run(cmd, capture_output=True, text=True)
            if out.returncode != 0:
                PACK["error"] = f"{' '.join(cmd)}: exit status {out.returncode}: {out.stderr.strip()}"
                return
        PACK["path"] = str(folder / "skin.ktx2")

    PACK["thread"] = threading.Thread(target=work, daemon=True)
    PACK["thread"].start()


def watch_engine():
    """Record the errors of the engine's viewport path (its export, its sunbeam-play runs) and
    whether a run is going on, by wrapping the two functions engine.py calls (they still run as
    they are; the add-on reports the same errors itself)."""
    from sunbeam_blender import engine, export
    build_scene, preview_frame = export.build_scene, engine.preview_frame

    def watched_build_scene(*args, **kwargs):
        try:
            return build_scene(*args, **kwargs)
        except Exception as e:
            ENGINE_ERRORS.append(f"viewport export: {e}")
            raise

    def watched_preview_frame(scene_json, frame, frames, cancelled):
        PLAY_RUNS["started"] += 1
        PLAY_RUNS["running"] += 1
        try:
            out = preview_frame(scene_json, frame, frames, lambda: PLAY_RUNS["quit"] or cancelled())
            PLAY_RUNS["finished"] = time.monotonic()
            return out
        except engine.Cancelled:
            raise
        except Exception as e:
            ENGINE_ERRORS.append(f"viewport sunbeam-play: {e}")
            raise
        finally:
            PLAY_RUNS["running"] -= 1

    frame_texture = engine._frame_texture

    def watched_frame_texture(path):
        texture = frame_texture(path)
        PLAY_RUNS["shown"] += 1  # view_draw has the frame as a texture: it draws it now
        return texture

    export.build_scene, engine.preview_frame = watched_build_scene, watched_preview_frame
    engine._frame_texture = watched_frame_texture


def setup():
    sys.path.insert(0, str(ADDON_DIR))
    import addon_utils
    addon_utils.enable(ADDON, default_set=True, handle_error=None)
    if ADDON not in bpy.context.preferences.addons:
        raise RuntimeError(f"the add-on {ADDON} did not enable (see the messages above)")
    make_pack()
    watch_engine()
    # The Scales sub-panel is closed by default; open it for the picture (a click on its header
    # does the same; this script has no mouse), by registering it again without DEFAULT_CLOSED
    # before the window first draws the Object tab.
    scales = bpy.types.SUNBEAM_PT_orientation_scales
    bpy.utils.unregister_class(scales)
    scales.bl_options = set()
    bpy.utils.register_class(scales)

    scene = bpy.context.scene
    for ob in list(scene.objects):
        if ob.type == "MESH":
            bpy.data.objects.remove(ob)
    mesh = bpy.data.meshes.new("Sphere")
    import bmesh
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=32, v_segments=16, radius=1.0, calc_uvs=True)
    bm.to_mesh(mesh)
    bm.free()
    ob = bpy.data.objects.new("Sphere", mesh)
    scene.collection.objects.link(ob)
    mat = bpy.data.materials.new("Snake Skin")
    mat.sunbeam.enabled = True
    mat.sunbeam.pack = "//packs/elaphe.ktx2"
    mesh.materials.append(mat)
    ob.sunbeam.use_scales = True
    for o in scene.objects:
        o.select_set(False)
    ob.select_set(True)
    bpy.context.view_layer.objects.active = ob
    scene.render.engine = "SUNBEAM"


def window():
    return bpy.context.window_manager.windows[0]


def area_of(kind):
    return next(a for a in window().screen.areas if a.type == kind)


def maximise_properties():
    """The Properties editor over the whole window (View > Area > Toggle Maximize Area): the
    virtual display's size (panel_screenshots.sh) makes that a tall, editor-wide window."""
    win = window()
    props = area_of("PROPERTIES")
    with bpy.context.temp_override(window=win, area=props):
        r = bpy.ops.screen.screen_full_area()
    if r != {"FINISHED"}:
        raise RuntimeError(f"screen.screen_full_area: {r}")


PANEL_SHOTS = [
    ("RENDER", "blender-panel-render.png"),
    ("MATERIAL", "blender-panel-material.png"),
    ("OBJECT", "blender-panel-object.png"),
]


def steps():
    """The work, as a generator: each `yield` lets the window redraw for SETTLE_S."""
    maximise_properties()
    yield
    win = window()
    props = area_of("PROPERTIES")
    space = props.spaces.active
    print(f"panel_screenshots: Blender {bpy.app.version_string}, window {win.width} x {win.height}, "
          f"Properties editor {props.width} x {props.height}")
    for tab, name in PANEL_SHOTS:
        space.context = tab
        yield
        shot = TMP / f"{tab}.png"
        with bpy.context.temp_override(window=win, area=props):
            r = bpy.ops.screen.screenshot_area(filepath=str(shot))
        if r != {"FINISHED"} or not shot.is_file():
            fail(f"screenshot_area of the {tab} tab: {r}")
            continue
        w, h, rows = read_png(shot)
        write_png(OUT / name, trim_bottom(rows))

    # File > Import: the menu as Blender pops it up (wm.call_menu), cropped to the pixels that
    # changed when it opened. Header: "Import", the add-on's entry at the end.
    space.context = "RENDER"
    yield
    # The menu opens with its first entry under the pointer: put that where the tab is empty.
    win.event_simulate(type="MOUSEMOVE", value="NOTHING", x=260, y=win.height - 440)
    yield
    before = TMP / "before.png"
    with bpy.context.temp_override(window=win):
        bpy.ops.screen.screenshot(filepath=str(before))
    props = area_of("PROPERTIES")  # the maximised editor is a new area
    region = next(r for r in props.regions if r.type == "WINDOW")
    with bpy.context.temp_override(window=win, area=props, region=region):
        r = bpy.ops.wm.call_menu(name="TOPBAR_MT_file_import")
    if not r & {"INTERFACE", "FINISHED"}:
        fail(f"wm.call_menu(TOPBAR_MT_file_import): {r}")
    yield
    first = TMP / "first.png"
    with bpy.context.temp_override(window=win):
        bpy.ops.screen.screenshot(filepath=str(first))
    _, _, a = read_png(before)
    w, h, b = read_png(first)
    box = changed_box(a, b)
    if box is None:
        fail("File > Import: the menu did not appear in the screenshot")
        return
    # Move the pointer onto the add-on's entry, the last one, which highlights it (Blender's
    # window coordinates count from the bottom). A busy machine may draw the menu before it
    # takes the move (CI once got the menu without the highlight): move again and take the
    # screenshot again until the entry's rows differ from the menu's first picture.
    x0, y0, x1, y1 = box
    _, _, menu = read_png(first)
    entry = range(max(y0, y1 - 24), y1 - 8)
    after = TMP / "after.png"
    for attempt in range(HIGHLIGHT_TRIES):
        win.event_simulate(type="MOUSEMOVE", value="NOTHING", x=x0 + 80 + attempt % 2, y=h - (y1 - 16))
        yield
        with bpy.context.temp_override(window=win):
            bpy.ops.screen.screenshot(filepath=str(after))
        w, h, b = read_png(after)
        if any(b[y] != menu[y] for y in entry):
            print(f"panel_screenshots: import menu entry highlighted after {attempt + 1} pointer move(s)")
            break
    else:
        fail(f"File > Import: the add-on's entry was not highlighted after {HIGHLIGHT_TRIES} pointer moves")
    box = changed_box(a, b)
    x0, y0, x1, y1 = box
    m = 8
    write_png(OUT / "blender-panel-import-menu.png",
              crop(b, max(0, x0 - m), max(0, y0 - m), min(w, x1 + m), min(h, y1 + m)))
    win.event_simulate(type="ESC", value="PRESS")
    win.event_simulate(type="ESC", value="RELEASE")
    yield
    yield from viewport_steps()


# ---- the viewport's rendered mode ----

def viewport_scene():
    """The real pack on the sphere's material, the factory lamp as a sun from behind the view's
    left shoulder, the factory camera (kept) looking at the sphere."""
    from mathutils import Vector
    PACK["thread"].join()
    if PACK["error"]:
        raise RuntimeError(f"making the viewport's pack: {PACK['error']}")
    scene = bpy.context.scene
    # UVs for the Scales bake (the panels' sphere has none: its pictures stay as they were).
    import bmesh
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_uvsphere(bm, u_segments=32, v_segments=16, radius=1.0, calc_uvs=True)
    bm.to_mesh(bpy.data.objects["Sphere"].data)
    bm.free()
    bpy.data.materials["Snake Skin"].sunbeam.pack = PACK["path"]
    cam = scene.camera
    if cam is None:
        raise RuntimeError("the factory scene has no camera")
    view_dir = (Vector((0, 0, 0)) - cam.location).normalized()  # the camera looks at the origin
    cam.rotation_euler = (-view_dir).to_track_quat("Z", "Y").to_euler()
    lamp = next((o for o in scene.objects if o.type == "LIGHT"), None)
    if lamp is None:
        raise RuntimeError("the factory scene has no lamp")
    lamp.data.type = "SUN"
    lamp.data.energy = 4.0
    left = view_dir.cross(Vector((0, 0, 1))).normalized() * -1.0
    towards_sun = (-view_dir + 0.6 * left + 0.5 * Vector((0, 0, 1))).normalized()
    lamp.rotation_euler = towards_sun.to_track_quat("Z", "Y").to_euler()  # a sun shines along -Z
    scene.sunbeam.preview_frames = 1
    # A black World: the factory one's grey would become a constant environment map, whose
    # first frame on a CPU rasteriser (Mesa's, here) takes minutes.
    world = scene.world
    world.use_nodes = False
    world.color = (0.0, 0.0, 0.0)
    return cam


def viewport_steps():
    try:
        import numpy  # noqa: F401
    except ImportError:
        raise RuntimeError("Blender's Python has no numpy, which its glTF exporter (run by the "
                           "engine's export) needs: install it (Debian: apt-get install python3-numpy)")
    win = window()
    props = area_of("PROPERTIES")  # still maximised
    with bpy.context.temp_override(window=win, area=props):
        r = bpy.ops.screen.back_to_previous()
    if r != {"FINISHED"}:
        raise RuntimeError(f"screen.back_to_previous: {r}")
    yield
    view3d = area_of("VIEW_3D")
    with bpy.context.temp_override(window=win, area=view3d):
        r = bpy.ops.screen.screen_full_area()
    if r != {"FINISHED"}:
        raise RuntimeError(f"screen.screen_full_area (3D Viewport): {r}")
    yield
    cam = viewport_scene()
    view3d = area_of("VIEW_3D")  # the maximised viewport is a new area
    space = view3d.spaces.active
    region = next(r for r in view3d.regions if r.type == "WINDOW")
    rv3d = space.region_3d
    space.overlay.show_overlays = False
    space.show_gizmo = False
    rv3d.view_perspective = "PERSP"
    rv3d.view_location = (0.0, 0.0, 0.0)
    rv3d.view_rotation = cam.rotation_euler.to_quaternion()
    rv3d.view_distance = 4.5
    yield
    print(f"panel_screenshots: 3D Viewport {view3d.width} x {view3d.height}, "
          f"its view {region.width} x {region.height}")
    start = time.monotonic()
    space.shading.type = "RENDERED"
    # The engine's frame: view_draw has made a texture of a finished sunbeam-play frame and no
    # run goes on (a run for an earlier view is cancelled by the next one).
    while True:
        yield 0.5
        if ENGINE_ERRORS:
            fail("the engine's viewport reported: " + "; ".join(ENGINE_ERRORS))
            return
        drawn = PLAY_RUNS["shown"] > 0
        if drawn and PLAY_RUNS["running"] == 0:
            break
        if PLAY_RUNS["finished"] and not PLAY_RUNS["running"] and time.monotonic() - PLAY_RUNS["finished"] > 10:
            fail("sunbeam-play wrote the viewport's frame but the engine did not draw it within 10 s "
                 "(its view_draw failed? see Blender's messages above)")
            return
        if time.monotonic() - start > VIEWPORT_TIMEOUT_S:
            fail(f"the engine drew no viewport frame within {VIEWPORT_TIMEOUT_S} s "
                 f"({PLAY_RUNS['started']} sunbeam-play runs started, frames shown: {PLAY_RUNS['shown']})")
            return
    print(f"panel_screenshots: the viewport's frame after {time.monotonic() - start:.1f} s "
          f"({PLAY_RUNS['started']} sunbeam-play run(s))")
    yield  # the frame drawn
    shot = TMP / "viewport.png"
    with bpy.context.temp_override(window=win, area=view3d):
        r = bpy.ops.screen.screenshot_area(filepath=str(shot))
    if r != {"FINISHED"} or not shot.is_file():
        fail(f"screenshot_area of the 3D Viewport: {r}")
        return
    if ENGINE_ERRORS:
        fail("the engine's viewport reported: " + "; ".join(ENGINE_ERRORS))
        return
    w, h, rows = read_png(shot)
    # The sphere's centre and radius in the screenshot (rows from the top): its centre and a
    # point of its silhouette's edge projected by the view.
    from bpy_extras.view3d_utils import location_3d_to_region_2d
    from mathutils import Vector
    c = location_3d_to_region_2d(region, rv3d, Vector((0, 0, 0)))
    right = rv3d.view_rotation @ Vector((1, 0, 0))
    e = location_3d_to_region_2d(region, rv3d, right)
    if c is None or e is None:
        fail("the sphere is not in the viewport's view")
        return
    radius = (e - c).length  # a little under the silhouette's (perspective): fine for the check
    ox, oy = region.x - view3d.x, region.y - view3d.y  # the view in the area (from the bottom)
    cx, cy = ox + c.x, h - 1 - (oy + c.y)
    check_viewport(rows, w, h, cx, cy, radius, (ox, h - oy - region.height, ox + region.width, h - oy))
    side = min(w, h, int(2.6 * radius))
    x0 = max(0, min(w - side, int(cx - side / 2)))
    y0 = max(0, min(h - side, int(cy - side / 2)))
    write_png(OUT / VIEWPORT_PNG, crop(rows, x0, y0, x0 + side, y0 + side))
    yield from f12_steps(win, view3d, space, cam)


# ---- F12 in the UI: the engine's render() in Blender's render job thread ----

def watch_render():
    """Record what the engine's final render does: each render() call, the exceptions it
    raises and the errors it reports (engine.py turns SunbeamError / OSError into
    self.report({'ERROR'}, ...)), and whether Blender's render job completed or was cancelled."""
    from sunbeam_blender import engine
    cls = engine.SunbeamRenderEngine
    render = cls.render

    class Reporting:
        """The engine as render() sees it, its report() recorded (an RNA function: the class's
        attribute cannot be replaced)."""

        def __init__(self, eng):
            self._eng = eng

        def __getattr__(self, name):
            return getattr(self._eng, name)

        def report(self, type, message):
            if {"ERROR", "ERROR_INVALID_INPUT", "ERROR_OUT_OF_MEMORY"} & set(type):
                RENDER["errors"].append(f"the engine reported: {message}")
            return self._eng.report(type, message)

    def watched_render(self, depsgraph):
        RENDER["calls"] += 1
        RENDER["thread"] = threading.current_thread() is not threading.main_thread()
        try:
            return render(Reporting(self), depsgraph)
        except Exception as e:
            RENDER["errors"].append(f"render() raised {type(e).__name__}: {e}")
            raise

    cls.render = watched_render

    def done(key):
        def handler(*_):
            RENDER[key] = True
        return handler

    bpy.app.handlers.render_complete.append(done("complete"))
    bpy.app.handlers.render_cancel.append(done("cancel"))


RENDER = {"calls": 0, "thread": None, "errors": [], "complete": False, "cancel": False}
F12_SIZE = (64, 48)
F12_SAMPLES = 4
F12_TIMEOUT_S = 120


def f12_steps(win, view3d, space, cam):
    """F12 as in the UI: render.render('INVOKE_DEFAULT') from the window, which runs the
    engine's render() in Blender's render job thread and opens the render view; then the Render
    Result must show the sphere lit at its projected centre."""
    space.shading.type = "SOLID"  # no preview runs meanwhile
    t = time.monotonic()
    while PLAY_RUNS["running"] and time.monotonic() - t < 30:
        yield 0.5
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = F12_SIZE
    scene.render.resolution_percentage = 100
    scene.render.use_lock_interface = True  # as docs/BLENDER.md advises
    scene.render.image_settings.file_format = "PNG"
    scene.sunbeam.samples = F12_SAMPLES
    watch_render()
    yield
    region = next(r for r in view3d.regions if r.type == "WINDOW")
    start = time.monotonic()
    with bpy.context.temp_override(window=win, area=view3d, region=region):
        r = bpy.ops.render.render("INVOKE_DEFAULT")
    if r != {"RUNNING_MODAL"}:
        fail(f"render.render('INVOKE_DEFAULT') (F12): {r}")
        return
    while True:
        yield 0.5
        ended = RENDER["complete"] or RENDER["cancel"]
        if ended and not bpy.app.is_job_running("RENDER"):
            break
        if time.monotonic() - start > F12_TIMEOUT_S:
            fail(f"F12: the render job did not end within {F12_TIMEOUT_S} s (render() called "
                 f"{RENDER['calls']} time(s), job running: {bpy.app.is_job_running('RENDER')})")
            return
    print(f"panel_screenshots: F12 render job ended after {time.monotonic() - start:.1f} s: "
          f"{'completed' if RENDER['complete'] else 'cancelled'}, render() called {RENDER['calls']} "
          f"time(s), in a thread other than the main one: {RENDER['thread']}")
    if RENDER["cancel"] or not RENDER["complete"]:
        fail("F12: the render job was cancelled (render_cancel), not completed")
    if RENDER["calls"] != 1 or not RENDER["thread"]:
        fail(f"F12: the engine's render() ran {RENDER['calls']} time(s), in the job thread: "
             f"{RENDER['thread']} (want once, in the job thread)")
    if RENDER["errors"]:
        fail("F12: " + "; ".join(RENDER["errors"]))
        return
    result = bpy.data.images.get("Render Result")
    if result is None:
        fail("F12: no 'Render Result' image")
        return
    png = TMP / "f12.png"
    result.save_render(filepath=str(png), scene=scene)
    if not png.is_file():
        fail("F12: Render Result's save_render wrote nothing")
        return
    w, h, rows = read_png(png)
    if (w, h) != F12_SIZE:
        fail(f"F12: the Render Result is {w} x {h}, not {F12_SIZE[0]} x {F12_SIZE[1]}")
        return
    from bpy_extras.object_utils import world_to_camera_view
    from mathutils import Vector
    c = world_to_camera_view(scene, cam, Vector((0, 0, 0)))  # from the bottom left, 0..1
    cx, cy = int(round(c.x * w)), int(round((1.0 - c.y) * h))

    def mean(x0, y0, n=8):
        vals = [v for y in range(y0, y0 + n) for v in rows[y][3 * x0:3 * (x0 + n)]]
        return sum(vals) / len(vals)

    centre = mean(cx - 4, cy - 4)
    corners = [mean(0, 0), mean(w - 8, 0), mean(0, h - 8), mean(w - 8, h - 8)]
    print(f"panel_screenshots: F12 check: Render Result {w} x {h}, {F12_SAMPLES} samples; the "
          f"sphere's centre at ({cx}, {cy}): mean of its 8 x 8 pixels {centre:.1f}, the corners' "
          f"{', '.join(f'{v:.1f}' for v in corners)} (0..255, the view transform applied)")
    if centre < max(corners) + 15:
        fail(f"F12: the Render Result's sphere is not lit (centre {centre:.1f}, corners up to "
             f"{max(corners):.1f}; want the centre >= 15 levels above every corner)")


def check_viewport(rows, w, h, cx, cy, radius, view_box):
    """Fail unless the sphere's disc differs clearly from the viewport's background: the mean
    colour of the disc's inner part against the mean of the view's pixels well outside it."""
    bx0, by0, bx1, by1 = view_box
    inner, outer = [], []
    for y in range(by0, by1, 2):
        row = rows[y]
        for x in range(bx0, bx1, 2):
            d = ((x - cx) ** 2 + (y - cy) ** 2) ** 0.5
            px = row[3 * x:3 * x + 3]
            if d < 0.7 * radius:
                inner.append(px)
            elif d > 1.4 * radius:
                outer.append(px)
    if len(inner) < 100 or len(outer) < 100:
        fail(f"the sphere's disc ({len(inner)} samples) or the background ({len(outer)}) is "
             "too small in the viewport's screenshot")
        return

    def mean(pxs):
        return [sum(p[i] for p in pxs) / len(pxs) for i in range(3)]

    mi, mo = mean(inner), mean(outer)
    dist = sum((a - b) ** 2 for a, b in zip(mi, mo)) ** 0.5
    # The disc's pixels that differ from the background's mean by more than 24 levels.
    far = sum(1 for p in inner if sum((p[i] - mo[i]) ** 2 for i in range(3)) ** 0.5 > 24) / len(inner)
    print(f"panel_screenshots: viewport check: the sphere's mean RGB {[round(v) for v in mi]}, "
          f"the background's {[round(v) for v in mo]}, distance {dist:.1f} levels, "
          f"{100 * far:.0f} % of the disc's pixels > 24 levels from the background")
    if dist < 20 or far < 0.5:
        fail(f"the viewport's sphere does not differ from its background (mean colour distance "
             f"{dist:.1f} levels, want >= 20; {100 * far:.0f} % of its pixels differ, want >= 50 %): "
             "the engine's frame was not drawn")


def main():
    bpy.context.preferences.view.show_splash = False
    OUT.mkdir(parents=True, exist_ok=True)
    try:
        setup()
    except Exception:
        traceback.print_exc()
        fail("set-up failed")
        quit_blender()
    gen = steps()

    def tick():
        try:
            wait = next(gen)
        except StopIteration:
            quit_blender()
            return None
        except Exception:
            traceback.print_exc()
            fail("a step failed")
            quit_blender()
            return None
        return SETTLE_S if wait is None else wait

    bpy.app.timers.register(tick, first_interval=SETTLE_S)


if bpy.app.background:
    print("panel_screenshots: Blender runs in background mode, where screenshots cannot be taken: "
          "run it with a window (tests/blender/panel_screenshots.sh)", file=sys.stderr)
    sys.exit(1)
main()
