"""Timing and peak resident memory of the peers, measured as uphill measures its own rows
(src/bench/support.hpp): before the work the kernel's high-water mark VmHWM is reset to the
current resident set (writing "5" to /proc/self/clear_refs), after it VmHWM is read. The figure
includes the interpreter, NumPy and the input arrays as resident when the work started.
"""
import time


def reset_peak():
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def peak_bytes():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024
    return 0


def measure(repeats, f, clock=time.thread_time):
    """(best seconds of `repeats` calls of f on `clock`, f's last result, peak RSS bytes or 0)."""
    ok = reset_peak()
    best, result = float("inf"), None
    for _ in range(repeats):
        t0 = clock()
        result = f()
        best = min(best, clock() - t0)
    return best, result, peak_bytes() if ok else 0
