#!/usr/bin/env python3
"""Build the Blender add-on's installable zip (Edit > Preferences > Add-ons > Install from Disk)
from integrations/blender/sunbeam_blender, byte-identical for the same sources: entries sorted,
fixed timestamps and permissions, no caches.

    scripts/blender-addon-zip.py OUT.zip
"""

import os
import sys
import zipfile
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "integrations" / "blender" / "sunbeam_blender"


def main(out):
    files = sorted(p for p in SRC.rglob("*") if p.is_file() and "__pycache__" not in p.parts)
    tmp = out + ".part"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for path in files:
            info = zipfile.ZipInfo(str(Path(SRC.name) / path.relative_to(SRC)), (1980, 1, 1, 0, 0, 0))
            info.external_attr = 0o644 << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, path.read_bytes())
    os.replace(tmp, out)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__.strip().splitlines()[-1].strip())
    main(sys.argv[1])
