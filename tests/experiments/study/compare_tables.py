"""Compares two kerf tables cell by cell — a study table (study.csv) or a force profile
(profile.csv) — apart from the cost columns (median, p99, max cost, the rate they allow, a
profile's cost_s: wall-time measurements that differ between any two runs). Numeric cells agree
to 1e-9 relative (round-off: a run beside others may sum in another order; a metric of exactly 0
serially came out 4e-15 with three jobs), every other cell exactly.
Exit 0 if they agree, 1 with the first difference otherwise."""
import csv
import math
import sys

RELATIVE = 1e-9


def without_costs(path):
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    if not rows:
        sys.exit(f"{path}: empty")
    keep = [k for k, name in enumerate(rows[0]) if "cost" not in name and "rate allowed" not in name]
    if len(keep) == len(rows[0]):
        sys.exit(f"{path}: no cost columns found (not a kerf study table or profile?)")
    return [[row[k] for k in keep if k < len(row)] for row in rows]


def number(cell):
    try:
        return float(cell)
    except ValueError:
        return None


def same(x, y):
    a, b = number(x), number(y)
    if a is None or b is None or math.isnan(a) or math.isnan(b):
        return x == y
    return abs(a - b) <= RELATIVE * max(1.0, abs(a), abs(b))


a, b = without_costs(sys.argv[1]), without_costs(sys.argv[2])
if len(a) != len(b):
    sys.exit(f"{len(a)} rows in {sys.argv[1]}, {len(b)} in {sys.argv[2]}")
for n, (x, y) in enumerate(zip(a, b), start=1):
    if len(x) != len(y) or not all(same(p, q) for p, q in zip(x, y)):
        sys.exit(f"line {n} differs:\n  {x}\n  {y}")
print(f"{len(a)} lines agree apart from the cost columns")
