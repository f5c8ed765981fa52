"""CPU-bound processes beside a run, to show what a busy machine does to it."""
import contextlib
import os
import signal
import subprocess


@contextlib.contextmanager
def busy_processes(count, seconds=600):
    """count CPU-bound processes, each ended by itself after `seconds` at the latest and by this
    context's exit in any case."""
    procs = [subprocess.Popen(['timeout', str(seconds), 'sh', '-c', 'while :; do :; done'],
                              start_new_session=True) for _ in range(count)]
    try:
        yield
    finally:
        for proc in procs:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
