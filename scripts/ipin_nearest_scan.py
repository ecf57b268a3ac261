#!/usr/bin/env python3
"""What one Wi-Fi scan can tell on an IPIN 2023 route, without RatSLAM.

Every scan of repetitions 02-04 of a route is matched to the single most similar scan of the
route's earlier repetitions (a map with a template at every scan: the densest a Wi-Fi map can
be), and the share whose true positions are within 5 m is printed per similarity:
  eq6      the Wi-Fi RatSLAM paper's eq. 6 with our shipped matcher settings (sigma^2 = 20 dBm^2,
           penalty 0.1 per dB above -90 dBm; sensors/wifi_fingerprint_matcher.h);
  eq6-off  the same with eq. 3 on RSSI differences around their mean (offset invariant);
  euclid   Euclidean distance over the union of APs, an unheard AP at -100 dBm (the usual
           k-NN representation, 1-NN here).
Ground truth is the POSI points, linearly interpolated; scans between points on different floors
(the stairs) and before the first or after the last point are left out. This is an independent
check written from the papers, not a call into our library.
Usage: /usr/bin/python3 scripts/ipin_nearest_scan.py [DATA_DIR]
"""
import bisect
import math
import os
import sys

VARIANCE = 20.0
PENALTY_FLOOR = -90.0
PENALTY_PER_DBM = 0.1
MIN_RSSI = -100.0


def load(path):
    """(time, (x, y), floor, {bssid: rssi}) per scan with ground truth."""
    scans, points = {}, []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            p = line.strip().rstrip(";").split(";")
            if p[0] == "WIFI" and len(p) >= 6:
                rssi = float(p[-1])
                if rssi >= MIN_RSSI:
                    scan = scans.setdefault(float(p[1]), {})
                    scan[p[4]] = max(rssi, scan.get(p[4], -1e9))
            elif p[0] == "POSI" and len(p) >= 6:
                points.append((float(p[1]), float(p[3]), float(p[4]), int(float(p[5]))))
    if not points:
        return []
    lat0 = points[0][1]
    metres_lon = 111320.0 * math.cos(math.radians(lat0))
    pts = [(t, (lon * metres_lon, lat * 110540.0), floor) for t, lat, lon, floor in points]
    times = [p[0] for p in pts]
    out = []
    for t, scan in sorted(scans.items()):
        i = bisect.bisect_left(times, t)
        if i == 0 or i >= len(pts) or pts[i - 1][2] != pts[i][2]:
            continue
        (ta, a, floor), (tb, b, _) = pts[i - 1], pts[i]
        w = (t - ta) / (tb - ta)
        out.append((t, (a[0] + w * (b[0] - a[0]), a[1] + w * (b[1] - a[1])), floor, scan))
    return out


def penalty(s):
    return PENALTY_PER_DBM * max(0.0, s - PENALTY_FLOOR)


def eq6(q, m, offset_invariant=False):
    common = [a for a in q if a in m]
    h = len(common)
    if h == 0:
        return 0.0
    d = [q[a] - m[a] for a in common]
    if offset_invariant:
        mean = sum(d) / h
        d = [x - mean for x in d]
    hit = math.exp(-sum(x * x for x in d) / (2 * VARIANCE) / h)
    extra = math.exp(-sum(penalty(q[a]) ** 2 for a in q if a not in m) / (2 * VARIANCE))
    missing = math.exp(-sum(penalty(m[a]) ** 2 for a in m if a not in q) / (2 * VARIANCE))
    return hit * extra * missing * h / (len(q) + len(m) - h)


def euclid(q, m):
    return -math.sqrt(sum((q.get(a, MIN_RSSI) - m.get(a, MIN_RSSI)) ** 2 for a in set(q) | set(m)))


SIMILARITIES = [("eq6", eq6), ("eq6-off", lambda q, m: eq6(q, m, True)), ("euclid", euclid)]


def main():
    data = sys.argv[1] if len(sys.argv) > 1 else "../shared/data/ipin2023-t3"
    print("| route | queries | " + " | ".join(f"{n} <=5 m" for n, _ in SIMILARITIES) + " |")
    print("|---|---|" + "---|" * len(SIMILARITIES))
    for route in ["01", "02", "03", "21", "22", "23"]:
        reps = []
        for rep in ["01", "02", "03", "04"]:
            path = os.path.join(data, f"IPIN2023_T3_TrainingTrial{route}_repetition{rep}.txt")
            if not os.path.exists(path):
                sys.exit(f"missing {path}")
            reps.append(load(path))
        rates = []
        queries = sum(len(r) for r in reps[1:])
        for _, similarity in SIMILARITIES:
            within = 0
            for k in range(1, len(reps)):
                earlier = [s for r in reps[:k] for s in r]
                for _, pos, floor, scan in reps[k]:
                    best = max(earlier, key=lambda c: similarity(scan, c[3]))
                    within += best[2] == floor and math.dist(pos, best[1]) <= 5.0
            rates.append(within / queries)
        print(f"| {route} | {queries} | " + " | ".join(f"{r:.2f}" for r in rates) + " |")


if __name__ == "__main__":
    main()
