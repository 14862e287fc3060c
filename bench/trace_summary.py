#!/usr/bin/env python3
"""GPU time per part of a TeGA training step, from a Chrome trace of
`train_bench --trace` (PyTorch's Kineto profiler).

Only kernels launched inside a training step (the `tega::step` scope) count,
not the checkpoint I/O or the held-out evaluation around them. Each is charged
to the innermost `tega::` scope around the op that launched it (see
TEGA_TRACE_SCOPE in avatar_model.cpp). Kernels launched by the autograd
engine are charged, through the op's sequence number, to the scope of the
forward op they differentiate, as "<part> backward".

It also reports the GPU's idle time inside the steps and the longest idle
gaps, each named by the part whose kernel ended it and by the kernels around
it: the GPU waited there for the host (a synchronisation, or ops launched
slower than they run); and the time from a step's start on the host to its
first kernel.

    bench/trace_summary.py TRACE.json [--top 25]
"""
import argparse
import bisect
import collections
import json


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("trace")
    ap.add_argument("--top", type=int, default=25)
    args = ap.parse_args()
    with open(args.trace) as f:
        events = json.load(f)["traceEvents"]

    ops = [e for e in events if e.get("ph") == "X" and e.get("cat") in ("cpu_op", "user_annotation")]
    kernels = [e for e in events if e.get("ph") == "X" and e.get("cat") in ("kernel", "gpu_memcpy", "gpu_memset")]

    # Innermost enclosing tega:: scope of every op, per thread, by time nesting.
    by_thread = collections.defaultdict(list)
    for op in ops:
        by_thread[op["tid"]].append(op)
    scope_of_op = {}
    for thread_ops in by_thread.values():
        thread_ops.sort(key=lambda e: (e["ts"], -e["dur"]))
        stack = []  # (end, scope)
        for op in thread_ops:
            while stack and stack[-1][0] < op["ts"]:
                stack.pop()
            inherited = stack[-1][1] if stack else None
            scope = op["name"][len("tega::"):] if op["name"].startswith("tega::") else inherited
            stack.append((op["ts"] + op["dur"], scope))
            scope_of_op[id(op)] = scope

    # Forward scope by sequence number, for the backward ops.
    forward_scope = {}
    for op in ops:
        seq = op.get("args", {}).get("Sequence number")
        if seq is not None and not op["name"].startswith("autograd::") and scope_of_op[id(op)]:
            forward_scope.setdefault(seq, scope_of_op[id(op)])
    backward_nodes = sorted(
        (op for op in ops if op["name"].startswith("autograd::engine::evaluate_function")),
        key=lambda e: e["ts"])
    node_starts = [op["ts"] for op in backward_nodes]

    def part_of(op):
        scope = scope_of_op[id(op)]
        i = bisect.bisect_right(node_starts, op["ts"]) - 1
        if i >= 0 and backward_nodes[i]["tid"] == op["tid"] and op["ts"] <= node_starts[i] + backward_nodes[i]["dur"]:
            seq = backward_nodes[i].get("args", {}).get("Sequence number")
            return f"{forward_scope.get(seq, 'other')} backward"
        return scope or "other"

    op_by_external = {}
    for op in ops:
        ext = op.get("args", {}).get("External id")
        if ext is not None:
            op_by_external[ext] = op  # later (inner) ops overwrite outer ones with the same id

    steps = sorted((op["ts"], op["ts"] + op["dur"]) for op in ops if op["name"] == "tega::step")
    step_starts = [s for s, _ in steps]

    def in_step(op):
        i = bisect.bisect_right(step_starts, op["ts"]) - 1
        return i >= 0 and op["ts"] <= steps[i][1]

    per_part = collections.Counter()
    per_kernel = collections.Counter()
    step_kernels = []  # (start, end, part)
    for k in kernels:
        op = op_by_external.get(k.get("args", {}).get("External id"))
        if op is None or not in_step(op):
            continue
        part = part_of(op)
        per_part[part] += k["dur"]
        per_kernel[(part, op["name"], k["name"][:80])] += k["dur"]
        step_kernels.append((k["ts"], k["ts"] + k["dur"], part, k["name"]))

    n = len(steps) or 1
    total = sum(per_part.values())
    print(f"GPU time per iteration: {total / 1000 / n:.2f} ms over {n} steps (kernels, memcpy and memset)")
    print("| part | ms / iteration | share |\n|---|---:|---:|")
    for part, us in per_part.most_common():
        print(f"| {part} | {us / 1000 / n:.2f} | {100 * us / total:.1f}% |")
    print_idle(step_kernels, n)
    print_host_lead(steps, step_kernels)
    print(f"\nTop {args.top} kernels:\n| part | launched by | kernel | ms / iteration |\n|---|---|---|---:|")
    for (part, op_name, name), us in per_kernel.most_common(args.top):
        print(f"| {part} | `{op_name}` | `{name}` | {us / 1000 / n:.2f} |")


def print_idle(step_kernels, steps, shown=8):
    """GPU idle time from the first step's first kernel to the last step's last, by the part that ended it."""
    if not step_kernels:
        return
    step_kernels.sort()
    gaps = []  # (length, part of the kernel after the gap, the kernels before and after it)
    busy_until, last_name = step_kernels[0][1], step_kernels[0][3]
    for start, end, part, name in step_kernels[1:]:
        if start > busy_until:
            gaps.append((start - busy_until, part, (last_name, name)))
        if end > busy_until:
            busy_until, last_name = end, name
    idle = sum(g for g, _, _ in gaps)
    span = busy_until - step_kernels[0][0]
    print(f"\nGPU idle from the first step's first kernel to the last step's last: {idle / 1000 / steps:.2f} ms per iteration "
          f"({100 * idle / span:.1f}% of {span / 1000 / steps:.2f} ms)")
    by_part = collections.Counter()
    for g, part, _ in gaps:
        by_part[part] += g
    print("| idle before a kernel of | ms / iteration | longest gap ms |\n|---|---:|---:|")
    for part, us in by_part.most_common(shown):
        longest = max(g for g, p, _ in gaps if p == part)
        print(f"| {part} | {us / 1000 / steps:.2f} | {longest / 1000:.2f} |")
    print("\nLongest gaps:\n| ms | after | before |\n|---:|---|---|")
    for g, _, (before, after) in sorted(gaps, reverse=True)[:shown]:
        print(f"| {g / 1000:.3f} | `{before[:60]}` | `{after[:60]}` |")


def print_host_lead(steps, step_kernels):
    """Time from each step's start on the host to its first kernel on the GPU."""
    starts = sorted(k[0] for k in step_kernels)
    leads = []
    for begin, end in steps:
        i = bisect.bisect_left(starts, begin)
        if i < len(starts) and starts[i] <= end:
            leads.append(starts[i] - begin)
    if leads:
        print(f"\nFrom a step's start on the host to its first kernel: {sum(leads) / len(leads) / 1000:.3f} ms on average")


if __name__ == "__main__":
    main()
