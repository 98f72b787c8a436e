#!/usr/bin/env python3
"""Write fuzz seeds: copies of ../shared/data samples and tiny synthetic files per target.
Usage: seeds.py CORPUS_DIR SHARED_DATA_DIR"""
import os, shutil, struct, sys

out, shared = sys.argv[1], sys.argv[2]
S = os.path.join(shared, "afm", "samples")
SN = os.path.join(shared, "snake")


def put(t, name, data):
    os.makedirs(os.path.join(out, t), exist_ok=True)
    with open(os.path.join(out, t, name), "wb") as f:
        f.write(data)


def cp(t, path):
    if os.path.exists(path):
        os.makedirs(os.path.join(out, t), exist_ok=True)
        shutil.copy(path, os.path.join(out, t))


def nano(bpp=2, ver="0x05310001", lines=4, samps=4):
    hdr = (f"\\*File list\r\n\\Version: {ver}\r\n\\Data length: HLEN\r\n\\*Scanner list\r\n"
           f"\\@Sens. Zscan: V 7.000000 nm/V\r\n\\*Ciao scan list\r\n\\Samps/line: {samps}\r\n\\Lines: {lines}\r\n"
           f"\\*Ciao image list\r\n\\Data offset: HLEN\r\n\\Data length: {bpp*lines*samps}\r\n\\Bytes/pixel: {bpp}\r\n"
           f"\\Samps/line: {samps}\r\n\\Number of lines: {lines}\r\n\\Scan size: 1.5 1.5 ~m\r\n"
           "\\@2:Image Data: S [Height] \"Height\"\r\n"
           "\\@2:Z scale: V [Sens. Zscan] (0.006539403 V/LSB) 41.60368 V\r\n\\*File list end\r\n")
    h2 = (len(hdr) + 64) // 64 * 64
    b = hdr.replace("HLEN", str(h2)).encode()
    return b + b"\0" * (h2 - len(b)) + bytes(range(bpp * lines * samps))


put("nanoscope", "small2", nano())
put("nanoscope", "small4", nano(4, "0x09700105", 3, 4))
cp("nanoscope", os.path.join(S, "topostats_old_bruker.002"))
cp("nanoscope", os.path.join(S, "header_only", "pySPM_bruker_data_header.000"))


def cstr(s):
    return s.encode() + b"\0"


def obj(name, comps):
    body = b"".join(comps)
    return cstr(name) + struct.pack("<I", len(body)) + body


def comp(n, t, v):
    return cstr(n) + t.encode() + v


def unit(s):
    return obj("GwySIUnit", [comp("unitstr", "s", cstr(s))])


df = obj("GwyDataField", [
    comp("xres", "i", struct.pack("<i", 3)), comp("yres", "i", struct.pack("<i", 2)),
    comp("xreal", "d", struct.pack("<d", 1e-6)), comp("yreal", "d", struct.pack("<d", 1e-6)),
    comp("si_unit_xy", "o", unit("m")), comp("si_unit_z", "o", unit("m")),
    comp("data", "D", struct.pack("<I", 6) + struct.pack("<6d", *range(6)))])
put("gwy", "small", b"GWYP" + obj("GwyContainer", [
    comp("/0/data", "o", df), comp("/0/data/title", "s", cstr("Height")),
    comp("/0/meta", "o", obj("GwyContainer", [comp("/x", "S", struct.pack("<I", 2) + b"a\0b\0")]))]))
cp("gwy", os.path.join(S, "gwyfile_test.gwy"))

h = b"Gwyddion Simple Field 1.0\nXRes = 3\nYRes = 2\nXReal = 1e-6\nYReal = 1e-6\nXYUnits = m\nZUnits = m\nTitle = H\n"
put("gsf", "small", h + b"\0" * (4 - len(h) % 4) + struct.pack("<6f", *range(6)))

wh = bytearray(320)
struct.pack_into("<i", wh, 12, 12)
struct.pack_into("<h", wh, 16, 2)
struct.pack_into("<h", wh, 26, 1)
wh[28:32] = b"wav\0"
struct.pack_into("<4i", wh, 68, 3, 2, 2, 0)
struct.pack_into("<4d", wh, 84, 1e-7, 1e-7, 1, 1)
wh[148:149] = b"m"
wh[152:153] = b"m"
wh[156:157] = b"m"
data = struct.pack("<12f", *range(12))
labels = b"\0" * 32 + b"Height".ljust(32, b"\0") + b"Phase".ljust(32, b"\0")
bh = struct.pack("<hhiiii4i4iiii", 5, 0, 320 + len(data), 0, 4, 0, 0, 0, 0, 0, 0, 0, len(labels), 0, 0, 0, 0)
put("ibw", "small", bh + bytes(wh) + data + b"note" + labels)
cp("ibw", os.path.join(S, "scifireaders_force_ibw.ibw"))

hdr = (b":NANONIS_VERSION:\n2\n:SCANIT_TYPE:\n  FLOAT  MSBFIRST\n:SCAN_PIXELS:\n   3   2\n:SCAN_RANGE:\n 1E-6 1E-6\n"
       b":SCAN_OFFSET:\n 0 0\n:SCAN_DIR:\nup\n:DATA_INFO:\n\tChannel\tName\tUnit\tDirection\tCalibration\tOffset\n"
       b"\t14\tZ\tm\tboth\t1\t0\n\n:SCANIT_END:\n\n\n\x1a\x04")
put("sxm", "small", hdr + struct.pack(">12f", *range(12)))
cp("park_tiff", os.path.join(S, "nanoAFMr_Park_20210916_034.tiff"))
cp("jpk", os.path.join(S, "topostats_file.jpk"))
cp("png", os.path.join(SN, "Elaph100x100.png"))
cp("png", os.path.join(S, "derived_by_gwyddion", "Veeco_20160622.003.height.grey16.png"))


def tiff16(w, h):
    ents = [(256, 3, 1, w), (257, 3, 1, h), (258, 3, 1, 16), (259, 3, 1, 1), (262, 3, 1, 1),
            (273, 4, 1, 8 + 2 + 12 * 8 + 4), (277, 3, 1, 1), (279, 4, 1, w * h * 2)]
    b = b"II*\0" + struct.pack("<I", 8) + struct.pack("<H", len(ents))
    for t, ty, c, v in ents:
        b += struct.pack("<HHII", t, ty, c, v)
    return b + struct.pack("<I", 0) + struct.pack(f"<{w*h}H", *range(w * h))


put("tiff", "small", tiff16(3, 2))
for f in ("BlazingBump.bmp", "SingleFingerElaphIdeal.bmp"):
    cp("bmp", os.path.join(SN, f))
put("ascii", "small", b"# Channel: Height\n# Width: 2 um\n# Height: 1 um\n# Value units: m\n1 2 3\n4 5 6\n")
put("ascii", "bare", b"1,2;3\n4 5 6\n")
put("xyz", "grid", b"".join(b"%g %g %g\n" % (i, j, i * j) for i in range(3) for j in range(3)))
put("xyz", "scatter", b"0 0 1\n1 0 2\n0 1 3\n0.3 0.4 5\n1 1 1\n")
# Nanosurf .nid, PicoView .mi, WSxM, NT-MDT: the samples and the small layout
# variants of crates/sunbeam-afm/tests/data/gwyddion_variants (in the repository).
V = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "crates", "sunbeam-afm",
                 "tests", "data", "gwyddion_variants")
for t, exts, samples in [
        ("nid", (".nid",), ["surfacetopography_nid-1.nid", "nsfopen_grid1.nid", "nsfopen_circles.nid"]),
        ("mi", (".mi",), ["surfacetopography_mi-1.mi"]),
        ("wsxm", (".top",), ["surfacetopography_top-1.top", "surfacetopography_stp-1.stp"]),
        ("mdt", (".mdt",), ["scifidatasets_test_mdt.mdt"])]:
    for f in samples:
        cp(t, os.path.join(S, f))
    if os.path.isdir(V):
        for f in sorted(os.listdir(V)):
            if f.endswith(exts):
                cp(t, os.path.join(V, f))
# Environment maps (sunbeam-light): Radiance RGBE, flat and run-length encoded.
hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n"
put("envmap", "flat.hdr", hdr + b"-Y 2 +X 4\n" + bytes([128, 64, 32, 129]) * 8)
rle_line = bytes([2, 2, 0, 8]) + b"".join(bytes([128 + 8, v]) for v in (100, 90, 80, 129))
put("envmap", "rle.hdr", hdr + b"-Y 4 +X 8\n" + rle_line * 4)
# The files sunbeam-pack --response writes (response map, environment maps,
# first-frame cells) for a tiny synthetic patch, when the tools are built.
B = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "target", "release")
if os.path.exists(os.path.join(B, "sunbeam-pack")):
    import subprocess, tempfile
    with tempfile.TemporaryDirectory() as d:
        h, p = os.path.join(d, "h.exr"), os.path.join(d, "p.ktx2")
        subprocess.run([os.path.join(B, "sunbeam-import"), "synthetic:xenopeltis",
                        "--synthetic-size", "16", "-q", "-o", h], check=True)
        subprocess.run([os.path.join(B, "sunbeam-pack"), h, "-o", p, "--response",
                        "--response-budget", "16KiB", "--response-lambda", "8",
                        "--response-cells", "2,4", "-q"], check=True)
        for f in ("p.response.ktx2", "p.env-response.ktx2", "p.env-cells.ktx2"):
            cp("response_files", os.path.join(d, f))
for t in os.listdir(out):
    if t == "detect":
        continue
    for f in os.listdir(os.path.join(out, t)):
        p = os.path.join(out, t, f)
        if os.path.getsize(p) < 400000:
            os.makedirs(os.path.join(out, "detect"), exist_ok=True)
            shutil.copy(p, os.path.join(out, "detect", f"{t}_{f}"))
