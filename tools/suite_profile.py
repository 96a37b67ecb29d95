"""Where the test suite's time goes: a summary of a ``SUITE_PROFILE`` log (see ``tests/conftest.py``).

Run the suite with ``SUITE_PROFILE=FILE`` set (``SUITE_PROFILE=/tmp/prof.jsonl ./test.sh -q``), then
``python tools/suite_profile.py FILE``: per xdist worker its busy time and the numba compile time its tests
paid; the slowest tests with the part of their time that was compilation; the kernels compiled inside the
suite (the candidates for ``tools/warm_kernels.py --more``), and those compiled by both workers; the time of
every xdist group (a group runs on one worker, in order).

Usage: ``python tools/suite_profile.py FILE [--top N]``
"""

from __future__ import annotations

import argparse
import collections
import json


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file")
    parser.add_argument("--top", type=int, default=30)
    args = parser.parse_args()
    recs = [json.loads(line) for line in open(args.file) if line.strip()]
    print(f"{len(recs)} tests; sum of wall {sum(r['wall'] for r in recs):.1f} s, of CPU "
          f"{sum(r['cpu'] + r.get('children_cpu', 0) for r in recs):.1f} s (subprocesses included), of numba "
          f"compile {sum(r['compile'] for r in recs):.1f} s (wall)")
    for w in sorted({r["worker"] for r in recs}):
        rs = [r for r in recs if r["worker"] == w]
        span = max(r["start"] + r["wall"] for r in rs) - min(r["start"] for r in rs)
        print(f"  worker {w}: {len(rs)} tests, span {span:.1f} s, busy {sum(r['wall'] for r in rs):.1f} s, "
              f"compile {sum(r['compile'] for r in rs):.1f} s")
    groups = collections.defaultdict(list)
    for r in recs:
        if r["group"]:
            groups[r["group"]].append(r)
    for g, rs in groups.items():
        print(f"  group {g}: {len(rs)} tests on {sorted({r['worker'] for r in rs})}, "
              f"{sum(r['wall'] for r in rs):.1f} s in all")
    print(f"\nslowest {args.top} tests (wall s, of it compile s, CPU s):")
    for r in sorted(recs, key=lambda r: -r["wall"])[:args.top]:
        print(f"  {r['wall']:7.1f} {r['compile']:7.1f} {r['cpu'] + r.get('children_cpu', 0):7.1f}  "
              f"[{r['worker']}] {r['test']}")
    per = collections.defaultdict(lambda: [0.0, 0, set(), None])
    for r in recs:
        for name, sig, t in r["kernels"]:
            e = per[(name, sig)]
            e[0] += t
            e[1] += 1
            e[2].add(r["worker"])
            e[3] = e[3] or r["test"]
    print(f"\nkernels compiled inside the suite, most expensive first ({len(per)} specialisations, "
          f"{sum(e[0] for e in per.values()):.1f} s; '2x': compiled by both workers):")
    for (name, sig), (t, n, ws, first) in sorted(per.items(), key=lambda kv: -kv[1][0])[:args.top]:
        print(f"  {t:7.1f} s {'2x' if len(ws) > 1 else '  '} {name} {sig[:70]}\n            first in {first}")
    both = [e[0] for e in per.values() if len(e[2]) > 1]
    print(f"compiled by both workers: {len(both)} specialisations, {sum(both):.1f} s")


if __name__ == "__main__":
    main()
