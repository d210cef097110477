#!/usr/bin/env python3
# CPU seconds of the transfer stage in a `perf record` (cpu-clock) of one vtbake bake: the
# sampled CPU time from the first to the last sample in transfer code (Transfer::,
# TransferTexture, the band cache, keep_channels). Unlike the bake's wall seconds it does not
# grow with other jobs on a shared machine (issue 16's side-by-side figures).
#   perf record -F 499 -o X.perf vtbake --threads 1 bake ...; bench/transfer_cpu_seconds.py X.perf
# Prints "CPU_SECONDS WINDOW_SECONDS".
import re
import subprocess
import sys

out = subprocess.run(["perf", "script", "-i", sys.argv[1], "-F", "time,period,ip,sym"],
                     capture_output=True, text=True, check=True).stdout
rows = []
for line in out.splitlines():
    m = re.match(r"\s*([\d.]+):\s+(\d+)\s+[0-9a-f]+\s*(.*)$", line)
    if m:
        rows.append((float(m.group(1)), int(m.group(2)), m.group(3)))
mark = re.compile(r"Transfer::|TransferTexture|TransferCache|transfer_materials|"
                  r"transfer_to_stores|sample_texture|keep_channels")
inside = [t for t, _, s in rows if mark.search(s)]
t0, t1 = min(inside), max(inside)
cpu = sum(p for t, p, _ in rows if t0 <= t <= t1) / 1e9
print("%.3f %.3f" % (cpu, t1 - t0))
