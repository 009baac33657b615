#!/usr/bin/env python3
"""Rebuilds this folder from the full traces: 20 ms bin means (50 Hz, the rate of seed 003),
two decimals. Usage: reduce.py SRC_DIR (e.g. ../shared/data/oxford_steps)."""
import csv, os, sys, shutil

src = sys.argv[1]
dst = os.path.dirname(os.path.abspath(__file__))
shutil.copy(os.path.join(src, "counts.csv"), dst)
for name in sorted(os.listdir(src)):
    if not name.endswith(".imu.csv"):
        continue
    bins = {}
    with open(os.path.join(src, name)) as f:
        for row in csv.DictReader(f):
            k = int(float(row["t_s"]) / 0.02)
            b = bins.setdefault(k, [0.0, 0.0, 0.0, 0])
            b[0] += float(row["ax_m_s2"]); b[1] += float(row["ay_m_s2"]); b[2] += float(row["az_m_s2"])
            b[3] += 1
    with open(os.path.join(dst, name), "w") as f:
        f.write("t_s,ax_m_s2,ay_m_s2,az_m_s2\n")
        for k in sorted(bins):
            b = bins[k]
            f.write("%.2f,%.2f,%.2f,%.2f\n" % (k * 0.02 + 0.01, b[0] / b[3], b[1] / b[3], b[2] / b[3]))
