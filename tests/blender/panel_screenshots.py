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
OUT_DIR/blender-panel-*.png as 8-bit RGB PNGs. Then it quits; any failure exits non-zero.
"""

import os
import struct
import sys
import tempfile
import traceback
import zlib
from array import array
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parents[2]
ADDON_DIR = ROOT / "integrations" / "blender"
ADDON = "sunbeam_blender"
SETTLE_S = 1.5  # seconds for the window to redraw after a change, before a screenshot

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
    for f in TMP.iterdir():
        f.unlink()
    TMP.rmdir()
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

def setup():
    sys.path.insert(0, str(ADDON_DIR))
    import addon_utils
    addon_utils.enable(ADDON, default_set=True, handle_error=None)
    if ADDON not in bpy.context.preferences.addons:
        raise RuntimeError(f"the add-on {ADDON} did not enable (see the messages above)")
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
    # window coordinates count from the bottom).
    x0, y0, x1, y1 = box
    win.event_simulate(type="MOUSEMOVE", value="NOTHING", x=x0 + 80, y=h - (y1 - 16))
    yield
    after = TMP / "after.png"
    with bpy.context.temp_override(window=win):
        bpy.ops.screen.screenshot(filepath=str(after))
    w, h, b = read_png(after)
    box = changed_box(a, b)
    x0, y0, x1, y1 = box
    m = 8
    write_png(OUT / "blender-panel-import-menu.png",
              crop(b, max(0, x0 - m), max(0, y0 - m), min(w, x1 + m), min(h, y1 + m)))


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
            next(gen)
        except StopIteration:
            quit_blender()
            return None
        except Exception:
            traceback.print_exc()
            fail("a step failed")
            quit_blender()
            return None
        return SETTLE_S

    bpy.app.timers.register(tick, first_interval=SETTLE_S)


if bpy.app.background:
    print("panel_screenshots: Blender runs in background mode, where screenshots cannot be taken: "
          "run it with a window (tests/blender/panel_screenshots.sh)", file=sys.stderr)
    sys.exit(1)
main()
