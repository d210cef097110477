#!/usr/bin/env python3
"""The modelled wall time of a 128K x 128K farm bake (docs/BENCHMARKS.md, "Build farm").

Per-core rates come from the sample-scene runs bench/farm_bench.sh makes (plan at 1 thread:
transfer and key pass per texel; one shard of all tasks at 1 thread: encode per page; merge per
page); they are scaled to a 131,072^2 atlas with the sample's coverage and layers, and combined
along the task graph's critical path: plan (serial: transfer, the pyramid pass, every level
written) -> shards (in parallel, each reads its own pages' rows of every level and encodes 1/M
of the pages) -> merge (serial).
Storage assumptions are parameters, printed with the table."""
import argparse
import json
import math


def stages(path):
    j = json.load(open(path))
    return j["seconds"], j


def main():
    a = argparse.ArgumentParser()
    a.add_argument("--plan", required=True)
    a.add_argument("--plan1", required=True)
    a.add_argument("--plan-graph", required=True)
    a.add_argument("--shards", nargs="+", required=True)
    a.add_argument("--shard-all", required=True)
    a.add_argument("--merge", required=True)
    a.add_argument("--side", type=int, default=131072)
    a.add_argument("--cores", type=int, default=16, help="cores per farm machine")
    a.add_argument("--node-gbps", type=float, default=2.0, help="GB/s one node reads shared storage")
    a.add_argument("--storage-gbps", type=float, default=20.0, help="GB/s the storage gives in all")
    a.add_argument("--slurm-s", type=float, default=3.0, help="scheduling latency per chained job")
    a.add_argument("--work-ratio", type=float, default=1.0,
                   help="raw floats / work-folder bytes: the plan's levels saved compressed "
                        "(scratch compressed: VirtualCity's 64K work folder measured it)")
    o = a.parse_args()

    plan, _ = stages(o.plan)
    plan1, _ = stages(o.plan1)
    graph = json.load(open(o.plan_graph))
    shard_all, sa = stages(o.shard_all)
    merge = json.load(open(o.merge))
    g = graph["geometry"]
    texels = g["width"] * g["height"]
    pages = sum(t["pages"] for t in graph["tasks"] if t["kind"] == "band")
    level0_bytes = sum(l["width"] * l["height"] * l["channels"] * 4 for l in graph["layers"])

    # Per-core rates at 1 thread.
    transfer_s_per_texel = plan1["transfer"] / texels
    keys_s_per_texel = plan1["keys"] / texels  # the pyramid pass without encoding
    encode_s_per_page = shard_all["build"] / pages  # a shard no longer runs the pyramid
    merge_s_per_page = merge["seconds"]["total"] / pages
    tables_s = plan1["plan"]
    print("measured on the sample scene (%dx%d atlas, %d layers, %d pages to encode):"
          % (g["width"], g["height"], len(graph["layers"]), pages))
    print("  plan at 2 threads: " + ", ".join("%s %.2f s" % kv for kv in plan.items()))
    print("  plan at 1 thread:  " + ", ".join("%s %.2f s" % kv for kv in plan1.items()))
    for s in o.shards:
        st, j = stages(s)
        print("  shard %s at 1 thread: %s" % (j["output"].split("/")[-1],
                                              ", ".join("%s %.2f s" % kv for kv in st.items())))
    print("  all tasks in one shard at 1 thread: " +
          ", ".join("%s %.2f s" % kv for kv in shard_all.items()))
    print("  merge %.3f s" % merge["seconds"]["total"])
    print("  per core: transfer %.1f ns/texel, pyramid pass %.1f ns/texel, encode %.2f ms/page, "
          "merge %.3f ms/page, tables %.2f s" %
          (transfer_s_per_texel * 1e9, keys_s_per_texel * 1e9, encode_s_per_page * 1e3,
           merge_s_per_page * 1e3, tables_s))

    scale = (o.side / g["width"]) ** 2
    T, P, L0 = texels * scale, pages * scale, level0_bytes * scale
    c = o.cores
    print("\nmodel: %d^2 atlas (%.3g texels, %.3g pages, level 0 %.0f GB as float), %d cores a "
          "machine, %.1f GB/s a node, %.0f GB/s storage in all, %.0f s Slurm latency a step, "
          "work files %.2fx smaller than raw floats"
          % (o.side, T, P, L0 / 1e9, c, o.node_gbps, o.storage_gbps, o.slurm_s, o.work_ratio))
    # Every level in working form, written once by the plan (bytes on shared storage).
    levels = L0 * 4 / 3 / o.work_ratio
    pyramid = keys_s_per_texel * T / c
    plan_s = transfer_s_per_texel * T / c + pyramid + tables_s + levels / (o.node_gbps * 1e9)
    merge_s = merge_s_per_page * P
    print("| machines | plan (serial: transfer, pyramid, levels written) | shard: read its rows | "
          "shard: encode | merge | total | speed-up |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    one = None
    for m in (1, 8, 64, 512):
        read = levels / m / (min(o.node_gbps, o.storage_gbps / m) * 1e9)
        encode = encode_s_per_page * P / (m * c)
        if m == 1:  # one machine: no farm, the one-process bake (no level round trip)
            total = (transfer_s_per_texel * T + encode_s_per_page * P + keys_s_per_texel * T) / c
            one = total
            print("| 1 (one process) | - | - | %.0f s | - | %.0f s (%.1f h) | 1.0 |"
                  % (encode, total, total / 3600))
            continue
        total = plan_s + read + encode + merge_s + 3 * o.slurm_s
        print("| %d | %.0f s | %.0f s | %.0f s | %.0f s | %.0f s (%.1f h) | %.1f |"
              % (m, plan_s, read, encode, merge_s, total, total / 3600, one / total))

    # On paper, the cut still needed to scale (not built): the transfer sharded by bands of rows
    # (it already runs in bands) ahead of one gather job that dilates, builds the pyramid once and
    # writes every level (what the plan does now after its own transfer).
    print("\nthe same on paper with the transfer sharded by row bands and one gather job "
          "(dilation + pyramid once, every level written) before the encode shards:")
    print("| machines | transfer shards | gather (serial) | encode shards | merge | total | "
          "speed-up |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    gather = L0 / o.work_ratio / (o.node_gbps * 1e9) + pyramid + levels / (o.node_gbps * 1e9)
    for m in (8, 64, 512):
        bw = min(o.node_gbps * m, o.storage_gbps) * 1e9
        transfer = transfer_s_per_texel * T / (m * c) + L0 / o.work_ratio / bw
        encode = encode_s_per_page * P / (m * c) + levels / bw
        total = transfer + gather + encode + merge_s + 4 * o.slurm_s
        print("| %d | %.0f s | %.0f s | %.0f s | %.0f s | %.0f s (%.1f h) | %.1f |"
              % (m, transfer, gather, encode, merge_s, total, total / 3600, one / total))


if __name__ == "__main__":
    main()
