"""Runs a command with CPU spinners beside it: the machine as busy as a shared CI runner or a
student's laptop with other work on it (`make test-under-load` runs the suite this way).

    python tests/busy_machine.py [--processes 8] [--max-seconds 3600] -- COMMAND [ARG...]

The spinners start before the command and stop when it ends, also when it fails, on Ctrl-C or on
SIGTERM; each also stops by itself after --max-seconds or when this process is gone (killed), so
none outlives its purpose. The exit status is the command's.
"""
import argparse
import signal
import subprocess
import sys

from onedof_harness.busy import busy_processes


def run_beside_spinners(command, processes, max_seconds):
    """Runs command with `processes` spinners beside it; returns the command's exit status."""
    child = None

    def forward_sigterm(signum, frame):
        if child is not None and child.poll() is None:
            child.send_signal(signum)

    def wait_for_the_command(signum, frame):
        """Ctrl-C reached the whole process group: the command ends on its own terms (pytest
        reports what ran) and this process goes on waiting for it. A handler, not
        KeyboardInterrupt: raised inside Popen.wait, the exception can drop the exit status just
        collected, and the next wait finds no child and reports 0."""

    handlers = {signal.SIGTERM: forward_sigterm}
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:  # else the command inherits SIG_IGN
        handlers[signal.SIGINT] = wait_for_the_command
    previous = {signum: signal.signal(signum, handler) for signum, handler in handlers.items()}
    try:
        with busy_processes(processes, max_seconds):
            child = subprocess.Popen(command)
            return child.wait()
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--processes', type=int, default=8, help='CPU spinners (default 8)')
    parser.add_argument('--max-seconds', type=float, default=3600,
                        help='the spinners stop by themselves after this long (default 3600)')
    parser.add_argument('command', nargs=argparse.REMAINDER, help='-- COMMAND [ARG...]')
    args = parser.parse_args(argv)
    command = args.command[1:] if args.command[:1] == ['--'] else args.command
    if not command:
        parser.error('no command given')
    print('busy_machine: %d CPU spinners beside: %s' % (args.processes, ' '.join(command)),
          flush=True)
    status = run_beside_spinners(command, args.processes, args.max_seconds)
    if status < 0:  # killed by a signal: the status a shell gives
        status = 128 - status
    print('busy_machine: spinners stopped; the command exited with %d' % status, flush=True)
    return status


if __name__ == '__main__':
    sys.exit(main())
