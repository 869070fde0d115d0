#!/usr/bin/env python3
# Localization report: runs the sim firmware on worlds and seeds and compares, from each trace,
# the firmware's estimate (est_) and the raw odometry (odo_) with the simulator's true pose.
"""Usage: tools/localization_report.py [--bin build/sim/bin/boticelli] [--realism realistic]
          [--seeds 1,2] [--max-cycles 45] [--no-register] [--config FILE] [--json] WORLD.sdf ...

Each run's configuration file sets `[sim] realism` and `[mission] register_looks = true`
(false with --no-register), then the lines of --config FILE (e.g. a [base] table with the
odometry's calibration).

Per run: result, cycles, driven path [m], final and worst position [m] and heading [deg]
error of the estimate and of the odometry (both in the mission frame, placed in the world by
the start pose, the first trace row's truth), looks registered and registration CPU per look
[ms] (the firmware's `mission cpu ... register_s= registered=` line), and the base's
calibration the registrations show (`mission base_calibration` line: track scale and wheel
diameter ratio with their standard errors, when valid)."""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


def compose(a, b):
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap(a[2] + b[2]))


def field(line, key):
    for part in line.split():
        if part.startswith(key + "="):
            try:
                return float(part[len(key) + 1:])
            except ValueError:
                return float("nan")
    return float("nan")


def run(binary, world, seed, cycles, realism, register, extra, tmp):
    trace = os.path.join(tmp, "trace.csv")
    conf = os.path.join(tmp, "sim.conf")
    with open(conf, "w") as f:
        f.write('[sim]\nrealism = "%s"\n' % realism)
        f.write("[mission]\nregister_looks = %s\n" % ("true" if register else "false"))
        f.write(extra)
    cmd = [binary, "--world", world, "--seed", str(seed), "--max-cycles", str(cycles),
           "--trace", trace, "--console", "stdio", "--config", conf]
    out = subprocess.run(cmd, stdin=subprocess.DEVNULL, capture_output=True, text=True).stdout
    r = {"world": os.path.basename(world).replace(".sdf", ""), "seed": seed,
         "realism": realism, "result": "?", "cycles": 0}
    for line in out.splitlines():
        line = line.strip()
        if line.startswith("MISSION "):
            r["result"] = line.split("result=")[1].split()[0]
            r["cycles"] = int(field(line, "cycles"))
            r["target_error_m"] = field(line, "target_error_m")
        elif "LOG info mission cpu " in line:
            looks = field(line, "registered")
            r["registered_looks"] = int(looks) if looks == looks else 0
            r["register_s"] = field(line, "register_s")
        elif "LOG info mission base_calibration " in line and field(line, "valid") == 1:
            r["calibration_intervals"] = int(field(line, "intervals"))
            r["odometry_track_scale"] = field(line, "odometry_track_scale")
            r["odometry_diameter_ratio"] = field(line, "odometry_diameter_ratio")
            sds = [p for p in line.split() if p.startswith("sd=")]
            r["track_scale_sd"] = float(sds[0][3:])
            r["diameter_ratio_sd"] = float(sds[1][3:])
    rows = []
    with open(trace) as f:
        header = f.readline().strip().split(",")
        col = {name: i for i, name in enumerate(header)}
        for line in f:
            v = line.strip().split(",")
            rows.append(v)
    get = lambda v, k: float(v[col[k]])
    start = (get(rows[0], "x_m"), get(rows[0], "y_m"), get(rows[0], "yaw_rad"))
    path = 0.0
    worst = {"est": [0.0, 0.0], "odo": [0.0, 0.0]}
    last = {}
    prev = None
    for v in rows:
        truth = (get(v, "x_m"), get(v, "y_m"), get(v, "yaw_rad"))
        if prev is not None:
            path += math.hypot(truth[0] - prev[0], truth[1] - prev[1])
        prev = truth
        for kind in ("est", "odo"):
            w = compose(start, (get(v, kind + "_x_m"), get(v, kind + "_y_m"),
                                get(v, kind + "_yaw_rad")))
            e_pos = math.hypot(w[0] - truth[0], w[1] - truth[1])
            e_yaw = abs(math.degrees(wrap(w[2] - truth[2])))
            worst[kind][0] = max(worst[kind][0], e_pos)
            worst[kind][1] = max(worst[kind][1], e_yaw)
            last[kind] = (e_pos, e_yaw)
    r["path_m"] = round(path, 2)
    for kind in ("est", "odo"):
        r[kind + "_final_m"] = round(last[kind][0], 3)
        r[kind + "_final_deg"] = round(last[kind][1], 2)
        r[kind + "_worst_m"] = round(worst[kind][0], 3)
        r[kind + "_worst_deg"] = round(worst[kind][1], 2)
    looks = r.get("registered_looks", 0)
    r["register_ms_per_look"] = (round(1e3 * r["register_s"] / max(r["cycles"], 1), 2)
                                 if "register_s" in r else float("nan"))
    r["registered_looks"] = looks
    return r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="build/sim/bin/boticelli")
    ap.add_argument("--realism", default="realistic")
    ap.add_argument("--seeds", default="1,2")
    ap.add_argument("--max-cycles", type=int, default=45)
    ap.add_argument("--no-register", action="store_true")
    ap.add_argument("--config", default="", help="more configuration lines for every run")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("worlds", nargs="+")
    a = ap.parse_args()
    runs = []
    extra = ""
    if a.config:
        with open(a.config) as f:
            extra = f.read()
    with tempfile.TemporaryDirectory() as tmp:
        for world in a.worlds:
            for seed in [int(s) for s in a.seeds.split(",")]:
                r = run(a.bin, world, seed, a.max_cycles, a.realism, not a.no_register, extra,
                        tmp)
                runs.append(r)
                if a.json:
                    print(json.dumps(r), flush=True)
                else:
                    print("%-28s %d %-9s cyc=%2d path=%5.1fm est final %.3fm %.2fdeg worst %.3fm "
                          "%.2fdeg | odo final %.3fm %.2fdeg worst %.3fm %.2fdeg | reg %d looks "
                          "%.2f ms/look" % (r["world"], r["seed"], r["result"], r["cycles"],
                                            r["path_m"], r["est_final_m"], r["est_final_deg"],
                                            r["est_worst_m"], r["est_worst_deg"], r["odo_final_m"],
                                            r["odo_final_deg"], r["odo_worst_m"],
                                            r["odo_worst_deg"], r["registered_looks"],
                                            r["register_ms_per_look"]), flush=True)
    found = sum(1 for r in runs if r["result"] == "found")
    summary = {"runs": len(runs), "found": found}
    for k in ("est_final_m", "est_final_deg", "odo_final_m", "odo_final_deg", "est_worst_m",
              "odo_worst_m", "register_ms_per_look"):
        vals = [r[k] for r in runs if r[k] == r[k]]
        if vals:
            summary[k + "_median"] = round(statistics.median(vals), 3)
            summary[k + "_max"] = round(max(vals), 3)
    print(json.dumps({"summary": summary}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
