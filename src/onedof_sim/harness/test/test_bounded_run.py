"""run_bounded: a program's output and status; a program that runs on past the bound is stopped
with SIGINT to its whole process group (Ctrl-C), and killed if it ignores that."""
from onedof_harness import bounded_run
from onedof_harness.bounded_run import run_bounded

# Longer than the programs here take to start on a busy machine; those that never end are
# stopped after it.
HANG_SECONDS = 20


def test_a_program_that_ends_gives_its_status_and_output():
    result = run_bounded(['sh', '-c', 'echo out; echo err >&2; exit 3'], HANG_SECONDS)
    assert (result.returncode, result.stdout, result.stderr) == (3, 'out\n', 'err\n')


def test_a_program_still_running_at_the_bound_is_stopped_as_ctrl_c_stops_it():
    result = run_bounded(['sh', '-c', 'trap "echo stopped by SIGINT; exit 5" INT; echo started; '
                          'while :; do sleep 1; done'], HANG_SECONDS)
    assert result.returncode == 'none: still running after %d s (a hang), stopped' % HANG_SECONDS
    assert result.stdout == 'started\nstopped by SIGINT\n'


def test_a_program_that_ignores_sigint_is_killed(monkeypatch):
    monkeypatch.setattr(bounded_run, 'STOP_SECONDS', 1)
    result = run_bounded(['sh', '-c', 'trap "" INT; echo started; while :; do sleep 1; done'],
                         HANG_SECONDS)
    assert result.returncode == 'none: still running after %d s (a hang), stopped' % HANG_SECONDS
    assert result.stdout == 'started\n'
