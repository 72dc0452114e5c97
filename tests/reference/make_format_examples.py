"""Writes the BOMEX sounding (scenes/bomex_sounding.csv) in the formats
meteorologists download, for tests/sounding_formats.rs: the University of
Wyoming TEXT:LIST listing and a SHARPpy %RAW% file, with heights above sea
level (a station 5 m up) and the formats' own rounding. Made by us from our
own sounding, not copied from any archive.

    python3 tests/reference/make_format_examples.py
"""

import csv
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
STATION_M = 5.0

rows = []
with open(os.path.join(ROOT, "scenes/bomex_sounding.csv")) as f:
    for r in csv.DictReader(line for line in f if not line.startswith("#")):
        rows.append((float(r["pressure_hPa"]), float(r["height_m"]) + STATION_M,
                     float(r["temperature_C"]), float(r["dewpoint_C"])))


def rh(t, td):
    es = lambda x: 6.112 * math.exp(17.67 * x / (x + 243.5))
    return 100.0 * es(td) / es(t)


out = os.path.join(ROOT, "tests/data/formats")
with open(os.path.join(out, "bomex_wyoming.txt"), "w") as f:
    f.write("BOMEX (our example) Observations at 12Z 22 Jun 1969\n\n")
    dash = "-" * 77 + "\n"
    f.write(dash)
    f.write("   PRES   HGHT   TEMP   DWPT   RELH   MIXR   DRCT   SKNT   THTA   THTE   THTV\n")
    f.write("    hPa     m      C      C      %    g/kg    deg   knot     K      K      K \n")
    f.write(dash)
    for p, h, t, td in rows:
        f.write(f"{p:7.1f}{h:7.0f}{t:7.1f}{td:7.1f}{rh(t, td):7.0f}"
                + " " * 42 + "\n")
    f.write("Station information and sounding indices\n")
    f.write("                         Station identifier: BMX\n")
with open(os.path.join(out, "bomex_sharppy.txt"), "w") as f:
    f.write("%TITLE%\n BMX   690622/1200\n\n")
    f.write("   LEVEL       HGHT       TEMP       DWPT       WDIR       WSPD\n")
    f.write("-" * 67 + "\n%RAW%\n")
    for p, h, t, td in rows:
        f.write(f"{p:8.2f}, {h:8.2f}, {t:8.2f}, {td:8.2f}, {90.0:8.2f}, {-9999.0:8.2f}\n")
    f.write("%END%\n")
with open(os.path.join(out, "bomex_igra2.txt"), "w") as f:
    # Header record, then levels in IGRA2's fixed columns (1-based):
    # LVLTYP1 1, LVLTYP2 2, ETIME 4-8, PRESS 10-15 (Pa), PFLAG 16,
    # GPH 17-21 (m), ZFLAG 22, TEMP 23-27 (0.1 C), TFLAG 28, RH 29-33
    # (0.1 %), DPDP 35-39 (0.1 C), WDIR 41-45, WSPD 47-51 (0.1 m/s).
    f.write(f"#BMX00000001 1969 06 22 12 1200 {len(rows):4d} ncdc-gts ncdc-gts  131000  -590000\n")
    for k, (p, h, t, td) in enumerate(rows):
        lvl = "21" if k == 0 else "10"
        f.write(f"{lvl} {-9999:5d} {round(p * 100):6d} {round(h):5d} {round(t * 10):5d} "
                f"{round(rh(t, td) * 10):5d} {round((t - td) * 10):5d} {90:5d} {-9999:5d}\n")
    f.write("#BMX00000001 1969 06 23 00 0000    1 ncdc-gts ncdc-gts  131000  -590000\n")
    f.write("21 -9999 101500     5   250 -9999    40    90 -9999\n")
print("wrote tests/data/formats/bomex_wyoming.txt, bomex_sharppy.txt and bomex_igra2.txt")
