#!/usr/bin/env python3
"""Instructions per ray from a callgrind profile of `plenum bench`, and where they go.

    valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file=cg.out \\
        /tmp/v3/release/plenum bench --mesh MESH --rays RAYS --threads 1 --passes 1
    docs/bench/callgrind_per_ray.py cg.out --rays N            # per-ray totals
    docs/bench/callgrind_per_ray.py cg.out --rays N --asm FUNCTION --binary BIN
    docs/bench/callgrind_per_ray.py cg.out --rays N --copies FUNCTION --binary BIN

With `--passes 1` the bench traces every ray twice (a warm-up and one pass) for each of the
closest and any hit, so N is twice the number of rays in the file. The totals are inclusive
(a function and all it calls) for TriangleMesh::intersect and intersect_any_as, which is what
one closest-hit and one any-hit ray cost; then the functions' own counts, largest first.
`--asm` prints the disassembly of one function (its full name, as listed) with how many
times each instruction ran, for reading where the count goes: a block test's gather, the
spills around a call, a node visit. `--copies` splits a function's count among its copies
(the monomorphised instances that share its name: the closest- and any-hit traversals, say),
each with how often it was entered, from the binary's symbol table. `--dump-instr=yes` is
needed for these two only.
Python 3 standard library and objdump.
"""

import argparse
import collections
import re
import subprocess
import sys

NAME = re.compile(r"^c?fn=\((\d+)\)(?: (.*))?$")


def parse(path):
    """Self and callee costs by function name, and self costs by instruction address."""
    names = {}
    own = collections.Counter()
    callees = collections.Counter()
    by_address = collections.defaultdict(collections.Counter)
    current = callee = None
    cost_is_call = False
    position_count = 1
    last = [0, 0]
    for line in open(path):
        line = line.rstrip("\n")
        if line.startswith("positions:"):
            position_count = len(line.split()) - 1
            continue
        match = NAME.match(line)
        if match:
            if match.group(2):
                names[match.group(1)] = match.group(2)
            if line.startswith("fn="):
                current = names[match.group(1)]
            else:
                callee = names[match.group(1)]
            continue
        if line.startswith("calls="):
            cost_is_call = True
            continue
        if not line or line[0] not in "0123456789+-*":
            continue
        fields = line.split()
        # Positions are absolute, relative to the previous line's (+n, -n) or the same (*).
        for i, token in enumerate(fields[:position_count]):
            if token == "*":
                continue
            if token[0] in "+-":
                last[i] += int(token[1:], 0) * (1 if token[0] == "+" else -1)
            else:
                last[i] = int(token, 0)
        cost = int(fields[position_count]) if len(fields) > position_count else 0
        if cost_is_call:
            cost_is_call = False
            if callee != current:
                callees[current] += cost
        else:
            own[current] += cost
            if position_count == 2:
                by_address[current][last[0]] += cost
    return own, callees, by_address


def print_asm(binary, counts):
    low, high = min(counts), max(counts)
    listing = subprocess.run(
        ["objdump", "-d", "--no-show-raw-insn", "-C",
         f"--start-address={low:#x}", f"--stop-address={high + 16:#x}", binary],
        capture_output=True, text=True, check=True).stdout
    for line in listing.splitlines():
        match = re.match(r"^\s*([0-9a-f]+):\s*(.*)$", line)
        if match:
            count = counts.get(int(match.group(1), 16), 0)
            print(f"{count:>10} {match.group(1)} {match.group(2)}")


def print_copies(binary, counts, rays):
    """Per copy of a function (by the symbols' addresses): instructions per ray and entry."""
    symbols = sorted({int(line.split()[0], 16) for line in subprocess.run(
        ["nm", binary], capture_output=True, text=True, check=True).stdout.splitlines()
        if len(line.split()) == 3 and line.split()[1] in "tTwW"})
    for start in sorted({max(s for s in symbols if s <= a) for a in counts}):
        end = min((s for s in symbols if s > start), default=float("inf"))
        total = sum(c for a, c in counts.items() if start <= a < end)
        entries = counts.get(start, 0)
        per_entry = f"{total / entries:8.1f} per entry" if entries else ""
        print(f"{start:#x}: {total / rays:8.1f} per ray, entered {entries / rays:6.3f} "
              f"times per ray {per_entry}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("profile")
    parser.add_argument("--rays", type=int, required=True,
                        help="traces of each kind: twice the file's rays with --passes 1")
    parser.add_argument("--asm", metavar="FUNCTION")
    parser.add_argument("--copies", metavar="FUNCTION")
    parser.add_argument("--binary", help="the profiled executable, for --asm and --copies")
    parser.add_argument("--top", type=int, default=8)
    args = parser.parse_args()
    own, callees, by_address = parse(args.profile)
    for name in sorted(own):
        if re.search(r"TriangleMesh::intersect(_any(_as)?)?$", name):
            total = (own[name] + callees[name]) / args.rays
            print(f"{name.rsplit('::', 1)[1]:>14}: {total:8.1f} instructions per ray")
    print("own instructions per ray:")
    for name, cost in own.most_common(args.top):
        print(f"{cost / args.rays:10.1f}  {name[:110]}")
    if args.asm:
        if not args.binary or args.asm not in by_address or not by_address[args.asm]:
            sys.exit("--asm needs --binary and a profile made with --dump-instr=yes")
        print_asm(args.binary, by_address[args.asm])
    if args.copies:
        if not args.binary or not by_address.get(args.copies):
            sys.exit("--copies needs --binary and a profile made with --dump-instr=yes")
        print_copies(args.binary, by_address[args.copies], args.rays)


if __name__ == "__main__":
    main()
