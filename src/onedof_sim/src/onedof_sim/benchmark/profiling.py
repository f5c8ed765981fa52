"""Profiles the benchmark takes where an aim is missed: perf for the C++ node, py-spy for a Python
controller. Each keeps its report in a file and returns one line saying where the time goes; a
missing or failing profiler is said plainly, never a failure of the run."""
import os
import shutil
import subprocess

from onedof_sim.benchmark import report as bm
from onedof_sim.tools import workspace_venv_bin


class NoProfile(Exception):
    """The profiler is missing or could not sample the process; str() says why."""


def take_profile(pid, seconds, path, python=False):
    """Profiles pid (perf, or py-spy for a Python process) into path; returns a one-line summary
    of where the time goes or, when the profiler is missing or fails, says so plainly."""
    try:
        return (pyspy_profile if python else perf_profile)(pid, seconds, path)
    except NoProfile as error:
        return 'no profile: %s' % error
    except (OSError, subprocess.SubprocessError) as error:
        return 'the profile failed: %s' % error


def perf_profile(pid, seconds, path):
    """On-CPU samples of a process and its threads with perf; the shares by shared object and
    the top symbols."""
    if not shutil.which('perf'):
        raise NoProfile('perf is not installed (Debian package linux-perf)')
    data = path[:-len('.txt')] + '.perf.data'
    recorded = subprocess.run(['perf', 'record', '-F', '1999', '-g', '-p', str(pid), '-o', data,
                               '--', 'sleep', str(seconds)],
                              capture_output=True, text=True, timeout=seconds + 60)
    if recorded.returncode != 0:
        raise NoProfile('perf record: ' + recorded.stderr[-300:])
    reports = []
    for sort in ('dso', 'dso,sym'):
        reports.append(subprocess.run(['perf', 'report', '-i', data, '--stdio', '--no-children',
                                       '-g', 'none', '--sort', sort, '--percent-limit', '0.5'],
                                      capture_output=True, text=True, timeout=120).stdout)
    os.remove(data)
    with open(path, 'w') as f:
        f.write('\n'.join(reports))
    objects = bm.perf_report_shares(reports[0])
    symbols = bm.perf_report_shares(reports[1])
    return 'perf, %g s of on-CPU samples: by object %s; top symbols %s' % (
        seconds, ', '.join('%s %.0f %%' % (os.path.basename(dso), pct)
                           for pct, dso, _ in objects[:5]),
        ', '.join('%s %.0f %%' % (sym[:60], pct) for pct, _, sym in symbols[:6]))


def pyspy_executable():
    """py-spy from the workspace venv (requirements.txt) or the PATH."""
    found = shutil.which('py-spy', path=os.pathsep.join(
        [workspace_venv_bin(), os.environ.get('PATH', '')]))
    if not found:
        raise NoProfile('py-spy is not installed (make venv installs it)')
    return found


def pyspy_profile(pid, seconds, path):
    """Python stacks of a process sampled by py-spy (the thread holding the GIL); the functions
    with the largest self and inclusive shares."""
    raw = path[:-len('.txt')] + '.stacks'
    # --gil: only the thread running Python code; threads blocked in a socket read would
    # otherwise look busy.
    recorded = subprocess.run([pyspy_executable(), 'record', '--format', 'raw', '--nonblocking',
                               '--gil',
                               '-d', str(seconds), '-p', str(pid), '-o', raw],
                              capture_output=True, text=True, timeout=seconds + 60)
    if recorded.returncode != 0:
        raise NoProfile('py-spy record: ' + (recorded.stderr or recorded.stdout)[-300:])
    with open(raw) as f:
        text = f.read()
    os.remove(raw)
    shares = bm.collapsed_stack_shares(text)
    by_self = sorted(shares.items(), key=lambda item: -item[1][0])
    by_inclusive = sorted(shares.items(), key=lambda item: -item[1][1])
    with open(path, 'w') as f:
        f.write('self %   inclusive %   function\n')
        for frame, (own, inclusive) in by_inclusive:
            f.write('%6.1f   %11.1f   %s\n' % (own * 100, inclusive * 100, frame))
    return 'py-spy, %g s of samples of the thread running Python: self %s; inclusive %s' % (
        seconds, ', '.join('%s %.0f %%' % (frame, own * 100) for frame, (own, _) in by_self[:6]),
        ', '.join('%s %.0f %%' % (frame, inclusive * 100)
                  for frame, (_, inclusive) in by_inclusive[:8]))
