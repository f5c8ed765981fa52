"""CPU-bound processes beside a run, to show what a busy machine does to it (the benchmark, the
tutorial's busy-machine test, and `make test-under-load` through tests/busy_machine.py)."""
import contextlib
import multiprocessing
import os
import signal
import time


def spin(deadline, parent):
    """Burns one CPU until the deadline (time.monotonic()) or until the parent process is gone."""
    # A forked spinner inherits its parent's handlers: with the parent's SIGTERM handler it would
    # outlive terminate() until the join gave up on it.
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, signal.SIG_DFL)
    while time.monotonic() < deadline and os.getppid() == parent:
        for _ in range(200000):
            pass


@contextlib.contextmanager
def busy_processes(count, seconds=600):
    """count CPU-bound processes for the context's duration; each also stops by itself after
    `seconds` or when this process is gone (killed), so none outlives its purpose."""
    deadline = time.monotonic() + seconds
    spinners = [multiprocessing.Process(target=spin, args=(deadline, os.getpid()), daemon=True,
                                        name='busy spinner %d' % i)
                for i in range(count)]
    for spinner in spinners:
        spinner.start()
    try:
        yield
    finally:
        for spinner in spinners:
            spinner.terminate()
        for spinner in spinners:
            spinner.join(timeout=10)
            if spinner.is_alive():
                spinner.kill()
                spinner.join()
