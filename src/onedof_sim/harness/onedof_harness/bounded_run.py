"""A program run to its end by a test, with a bound only against a hang: on a hang the program is
stopped as a user stops it (Ctrl-C: SIGINT to its process group, so that it stops the nodes it
started in sessions of their own), then killed with what is left of its group. subprocess.run's
own timeout kills the program alone and leaves its roscore and nodes running."""
import os
import signal
import subprocess

STOP_SECONDS = 60  # how long a program stopped with SIGINT may take to end before it is killed


def run_bounded(args, hang_seconds, **popen_args):
    """Runs args with text stdout and stderr captured; a CompletedProcess whose returncode is
    a sentence saying so when the program was still running after hang_seconds."""
    program = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True, **popen_args)
    try:
        stdout, stderr = program.communicate(timeout=hang_seconds)
        return subprocess.CompletedProcess(args, program.returncode, stdout, stderr)
    except subprocess.TimeoutExpired:
        os.killpg(program.pid, signal.SIGINT)
        try:
            stdout, stderr = program.communicate(timeout=STOP_SECONDS)
        except subprocess.TimeoutExpired:
            os.killpg(program.pid, signal.SIGKILL)
            stdout, stderr = program.communicate()
        return subprocess.CompletedProcess(
            args, 'none: still running after %d s (a hang), stopped' % hang_seconds, stdout,
            stderr)
