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
Two checks of what more than one scan adds, both with eq. 6:
  seq4     a sequence: the mean eq. 6 of the query's last 4 scans against 4 consecutive scans of
           one earlier repetition (aligned by index: scans come about every 4 s and the walks of
           a route take similar times), the last of the best 4 being the answer;
  ratio    an ambiguity test with an oracle: only queries whose best scan beats every scan more
           than 8 m from it (by true position, or on another floor) by a factor of 1 / 0.8 are
           answered; the share within 5 m of those, and the share answered. A map knows its
           places only as well as its own estimate, so this is a ceiling for any such test.
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


SEQUENCE = 4
RATIO = 0.8
AMBIGUOUS_BEYOND_M = 8.0


def is_within(query, answer):
    return answer[2] == query[2] and math.dist(query[1], answer[1]) <= 5.0


def multi_scan(reps):
    """(share within 5 m by seq4, share within 5 m of the answered by ratio, share answered)."""
    seq_within = ratio_within = answered = queries = 0
    for k in range(1, len(reps)):
        # eq. 6 of every scan of repetition k against every scan of each earlier one.
        sims = [[[eq6(q[3], m[3]) for m in reps[r]] for q in reps[k]] for r in range(k)]
        for i, query in enumerate(reps[k]):
            queries += 1
            best, best_score = None, -1.0
            for r in range(k):
                for j in range(len(reps[r])):
                    n = min(SEQUENCE, i + 1, j + 1)
                    score = sum(sims[r][i - d][j - d] for d in range(n)) / n
                    if score > best_score:
                        best, best_score = reps[r][j], score
            seq_within += is_within(query, best)
            ranked = sorted(((sims[r][i][j], reps[r][j]) for r in range(k)
                             for j in range(len(reps[r]))), key=lambda c: -c[0])
            top, answer = ranked[0]
            rival = next((s for s, c in ranked if c[2] != answer[2] or
                          math.dist(c[1], answer[1]) > AMBIGUOUS_BEYOND_M), 0.0)
            if top > 0 and rival <= RATIO * top:
                answered += 1
                ratio_within += is_within(query, answer)
    return (seq_within / queries, ratio_within / answered if answered else float("nan"),
            answered / queries)


def main():
    data = sys.argv[1] if len(sys.argv) > 1 else "../shared/data/ipin2023-t3"
    print("| route | queries | " + " | ".join(f"{n} <=5 m" for n, _ in SIMILARITIES) +
          f" | seq{SEQUENCE} <=5 m | ratio {RATIO}: <=5 m | answered |")
    print("|---|---|" + "---|" * (len(SIMILARITIES) + 3))
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
        rates.extend(multi_scan(reps))
        print(f"| {route} | {queries} | " + " | ".join(f"{r:.2f}" for r in rates) + " |")


if __name__ == "__main__":
    main()
