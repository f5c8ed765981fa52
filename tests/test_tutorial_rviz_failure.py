"""The main job when rviz dies: rviz is the one process the job may lose without failing. A dead
rviz is restarted and the screenshot taken from the new one (showing the final pose); when every
rviz dies, the job writes every other output, says that rviz_final.png is missing and why, and
exits non-zero. Each run starts from an output folder cleared of what an earlier run wrote there,
and of nothing else.

rviz is killed here with SIGABRT, as the C library kills it when it finds its heap corrupted."""
import os
import signal
import subprocess
import threading
import time

import psutil

from onedof_harness.private_ros import exit_status_text
from test_tutorial import RIGHT_OF_LINK1_ABOVE_TABLE, count_pixels, robot_red

# A short run: the first phase, and one sim second of it through the in-simulator PID.
ARGS = ['--phases', '1', '--phase-duration', '2', '--in-sim-phase-duration', '1']
RUN_OUTPUTS = {'phase1_command_1.0.png', 'tutorial.png', 'samples.csv', 'summary.md',
               'summary.json', 'phase1_command_1.0_pd_vs_pid.png', 'in_sim_samples.csv', 'logs'}
ABORTED = 'rviz exited (status -6, SIGABRT)'


def start_player(output):
    env = dict(os.environ)
    env.pop('DISPLAY', None)  # headless: the player brings its own Xvfb
    return subprocess.Popen(['rosrun', 'onedof_sim', 'play_tutorial', '--output', str(output)] +
                            ARGS, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env)


def rviz_processes(parent):
    """The rviz processes below `parent` (a Popen): the player's, or gzclient's view's."""
    try:
        return [proc for proc in psutil.Process(parent.pid).children(recursive=True)
                if proc.name() == 'rviz']
    except psutil.NoSuchProcess:
        return []


def abort(processes):
    for proc in processes:
        try:
            proc.send_signal(signal.SIGABRT)
        except psutil.NoSuchProcess:
            pass


def earlier_run(output):
    """An output folder as an earlier, longer run left it, with a file of the user's beside."""
    output.mkdir()
    (output / 'logs').mkdir()
    for name in ('rviz_final.png', 'phase4_table_2.5.png', 'summary.md', 'logs/earlier.log'):
        (output / name).write_text('from an earlier run')
    (output / 'notes.txt').write_text('the user\'s own')


def test_when_every_rviz_dies_the_job_writes_the_rest_and_says_the_screenshot_is_missing(
        tmp_path):
    output = tmp_path / 'output'
    earlier_run(output)
    player = start_player(output)
    aborted = []

    def abort_every_rviz():
        while player.poll() is None:
            found = rviz_processes(player)
            abort(found)
            aborted.extend(proc.pid for proc in found if proc.pid not in aborted)
            time.sleep(0.05)
    killer = threading.Thread(target=abort_every_rviz)
    killer.start()
    try:
        stdout, stderr = player.communicate(timeout=600)
    finally:
        player.kill()
        killer.join()

    assert player.returncode != 0, stdout[-3000:]
    assert player.returncode > 0, 'play_tutorial exited (%s):\n%s' % (
        exit_status_text(player.returncode), stderr[-3000:])
    assert 'every other output is written, but rviz_final.png is missing: rviz failed on all 3 ' \
           'tries' in stderr, stderr[-3000:]
    for attempt in (1, 2, 3):
        assert 'rviz try %d of 3 failed: %s' % (attempt, ABORTED) in stdout, stdout[-3000:]
    assert len(aborted) == 3
    # This run's outputs and the user's file, nothing of the earlier run.
    assert set(os.listdir(output)) == RUN_OUTPUTS | {'notes.txt'}
    assert (output / 'summary.md').read_text().startswith('# Tutorial summary')
    assert (output / 'notes.txt').read_text() == 'the user\'s own'
    assert not (output / 'logs' / 'earlier.log').exists()
    assert {'rviz.log', 'rviz_2.log', 'rviz_3.log'} <= set(os.listdir(output / 'logs'))


def test_an_rviz_that_dies_at_the_screenshot_is_restarted_and_shows_the_final_pose(tmp_path):
    output = tmp_path / 'output'
    earlier_run(output)
    player = start_player(output)
    stderr = []
    reader = threading.Thread(target=lambda: stderr.append(player.stderr.read()))
    reader.start()
    lines = []
    try:
        for line in player.stdout:
            lines.append(line)
            if 'rviz screenshot of the final pose' in line:
                running = rviz_processes(player)
                assert len(running) == 1, 'one rviz up through the phases'
                abort(running)
        player.wait(timeout=600)
    finally:
        player.kill()
        reader.join()
    stdout = ''.join(lines)

    assert player.returncode == 0, 'play_tutorial exited (%s):\n%s\n--- its stderr ---\n%s' % (
        exit_status_text(player.returncode), stdout[-3000:], ''.join(stderr)[-3000:])
    assert 'rviz try 1 of 3 failed: %s' % ABORTED in stdout
    # Only the first rviz was aborted. A restarted one can crash on its own as it starts (Mesa's
    # llvmpipe on LLVM 15 does now and then on a busy machine: README, "Seeing the sensors in
    # rviz"); the player then starts the next, and the final pose is still shown (below).
    assert 'rviz try 2 of 3 failed: %s' % ABORTED not in stdout
    # The restarted rviz was shown the final pose by one more control period of the world.
    after_failure = stdout[stdout.index('rviz try 1 of 3 failed'):]
    assert 'rosservice call /gazebo/step_simulation "steps: 10"' in after_failure
    assert set(os.listdir(output)) == RUN_OUTPUTS | {'rviz_final.png', 'notes.txt'}
    png = output / 'rviz_final.png'
    assert count_pixels(png, RIGHT_OF_LINK1_ABOVE_TABLE, robot_red) > 500, \
        'no robot-red pixels right of link1, where link2 holds at 1.49 rad'
