# Where a running mcslamd allocates: gdb breakpoints on the allocation functions in the chosen threads,
# a backtrace per hit, counted per call site; then gdb detaches (the daemon runs on).
#   HITS=3000 SECONDS_LIMIT=90 THREADS=mcslam-process,mcslamd OUT=sites.txt gdb -p PID -batch -x malloc_sites.py
# THREADS: thread names (prefixes); the pipeline's own workers are called "mcslamd" like the main thread.
# The sampling ends after HITS hits or SECONDS_LIMIT seconds (checked when the main thread's sigtimedwait
# ticks, every status interval). Interrupting gdb instead would deliver SIGINT to the daemon (a clean stop).
import collections
import os
import time

import gdb

N = int(os.environ.get("HITS", "400"))
LIMIT = float(os.environ.get("SECONDS_LIMIT", "60"))
NAMES = os.environ.get("THREADS", "mcslam-process,mcslamd,mcslam-replay,mcslam-assemble,mcslam-publish").split(",")
gdb.execute("set pagination off")
gdb.execute("set print frame-arguments none")
threads = [t for t in gdb.selected_inferior().threads() if t.name and any(t.name.startswith(n) for n in NAMES)]
print("threads:", [(t.num, t.name) for t in threads])
hits = []
t0 = time.time()


class Allocation(gdb.Breakpoint):
    def stop(self):
        f, names = gdb.newest_frame(), []
        while f is not None and len(names) < 14:
            names.append(f.name() or "??")
            f = f.older()
        hits.append(tuple(names))
        return len(hits) >= N


class Deadline(gdb.Breakpoint):
    def stop(self):
        return time.time() - t0 > LIMIT


breakpoints = []
for t in threads:
    for fn in ("malloc", "calloc", "realloc", "posix_memalign", "aligned_alloc"):
        b = Allocation(fn, internal=True)
        b.thread = t.num
        breakpoints.append(b)
deadline = Deadline("sigtimedwait", internal=True)
deadline.thread = 1
breakpoints.append(deadline)
gdb.execute("continue")
with open(os.environ.get("OUT", "sites.txt"), "w") as out:
    out.write("%d hits in %.0f s\n" % (len(hits), time.time() - t0))
    for stack, n in collections.Counter(hits).most_common():
        out.write("%5d  %s\n" % (n, " <- ".join(stack)))
for b in breakpoints:
    b.delete()
gdb.execute("detach")
