#!/bin/sh
# Gwyddion 2.62's reading of every variant file: gwyddion/<file>.<id>.f64/.txt
# (as ../../../../../../shared/data/afm/reference) and gwyddion/summary.txt
# (gwyref's output, LOAD FAILED lines included).
# Needs gwyref built from ../shared/tools/gwyref (build.sh): GWYREF=path/to/gwyref sh dump.sh
set -e
cd "$(dirname "$0")"
python3 make_variants.py .
rm -rf gwyddion && mkdir gwyddion
for f in *.nid *.mi *.top *.mdt; do
  GWYREF_DUMP=gwyddion "${GWYREF:-gwyref}" "$f" >> gwyddion/summary.txt 2>/dev/null || echo "FILE $f
  gwyref exit status $? (139: Gwyddion crashed)" >> gwyddion/summary.txt
done
