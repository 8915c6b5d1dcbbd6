#!/usr/bin/env python3
"""How long removing a just-written output set takes, its files one after the other against one
thread a file (issue 19, seventh session: OutputSet's remove_set).

    python3 bench/remove_set_model.py [DIR] [--rounds 8]

Writes two folders of eleven files of the default render's sizes into DIR (default /tmp), each
file written and fsynced, the folder fsynced, then the parent fsynced (as OutputSet::write does
before it removes the previous set), and times the removal of one of them: sequential unlinks
or one thread a file, alternating. Prints the sorted times in ms of each.
"""
import argparse
import os
import threading
import time

SIZES = [29065, 3200985, 89486, 1859, 907136, 131793, 142862, 2012588, 384, 142862, 202]


def fsync_dir(d):
    fd = os.open(d, os.O_RDONLY)
    os.fsync(fd)
    os.close(fd)


def make(d):
    os.makedirs(d, exist_ok=True)
    for i, s in enumerate(SIZES):
        with open(f"{d}/f{i}", "wb") as f:
            f.write(os.urandom(s))
            f.flush()
            os.fsync(f.fileno())
    fsync_dir(d)


def remove_sequential(d):
    for i in range(len(SIZES)):
        os.unlink(f"{d}/f{i}")
    os.rmdir(d)


def remove_side_by_side(d):
    threads = [threading.Thread(target=os.unlink, args=(f"{d}/f{i}",)) for i in range(len(SIZES))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    os.rmdir(d)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir", nargs="?", default="/tmp")
    ap.add_argument("--rounds", type=int, default=8)
    args = ap.parse_args()
    base = os.path.join(args.dir, f"remove-set-model-{os.getpid()}")
    os.makedirs(base)
    modes = {"one after the other": remove_sequential, "side by side": remove_side_by_side}
    times = {m: [] for m in modes}
    for r in range(args.rounds):
        for m in (list(modes) if r % 2 == 0 else list(modes)[::-1]):
            old, new = os.path.join(base, "old"), os.path.join(base, "new")
            make(old)
            make(new)
            fsync_dir(base)
            t = time.perf_counter()
            modes[m](old)
            times[m].append((time.perf_counter() - t) * 1000)
            remove_sequential(new)
    os.rmdir(base)
    for m, ts in times.items():
        print(f"{m:20s} " + " ".join(f"{x:.1f}" for x in sorted(ts)) + " ms")


if __name__ == "__main__":
    main()
