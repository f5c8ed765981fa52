"""The main job end to end: `play_tutorial` on a built workspace plays the whole tutorial and
writes every output; its figures are those of the in-process run of the same controller law to a
micro-radian, the same again with a busy process per core beside it, and agree with the closed-form
physics; its rviz screenshot shows the robot and the table. The same run plays the phases again
through the in-simulator PID (the book's YAML): it settles at the commands, and on the table."""
import fcntl
import json
import os

import pytest

from onedof_harness.bounded_run import run_bounded
from onedof_harness.busy import busy_processes
from onedof_sim.tutorial import physics
from onedof_sim.tutorial.player import job_outputs

from conftest import session_folder

PHASE_DURATION = 5.0
SAME = 1e-6  # rad: lock-step runs agree to this, whatever the machine is doing
# One per core: every process of the run waits its turn behind one, all through the run (more
# would only take more of the machine from the tests beside this one; make test-under-load runs
# the whole suite, this test included, beside 8 and 20).
BUSY_PROCESSES = os.cpu_count()
# Only a bound against a hang, not a speed test: a run takes minutes on a busy machine. Below the
# suite's per-test timeout (900 s) with the time to stop it, so that a hang fails with the
# player's output.
HANG_SECONDS = 780
OUTPUTS = ('phase1_command_1.0.png', 'phase2_command_2.0.png', 'phase3_upright_0.0.png',
           'phase4_table_2.5.png', 'tutorial.png', 'samples.csv', 'rviz_final.png', 'summary.md',
           'summary.json', 'phase1_command_1.0_pd_vs_pid.png', 'phase2_command_2.0_pd_vs_pid.png',
           'phase3_upright_0.0_pd_vs_pid.png', 'phase4_table_2.5_pd_vs_pid.png',
           'in_sim_samples.csv')


def play_tutorial(output, *args):
    env = dict(os.environ)
    env.pop('DISPLAY', None)  # headless: the player brings its own Xvfb
    result = run_bounded(['rosrun', 'onedof_sim', 'play_tutorial', '--output', str(output),
                          '--phase-duration', str(PHASE_DURATION)] + list(args), HANG_SECONDS,
                         env=env)
    return dict(returncode=result.returncode, stdout=result.stdout, stderr=result.stderr)


@pytest.fixture
def tutorial(tmp_path_factory):
    """The tutorial, played once per test session: every test here runs in its own forked process
    (and maybe another xdist worker), so the first one plays it under a lock and the others read
    what it wrote."""
    shared = session_folder(tmp_path_factory, 'tutorial_once')
    shared.mkdir(exist_ok=True)
    output = shared / 'output'
    with open(shared / 'lock', 'w') as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (shared / 'run.json').exists():
            run = play_tutorial(output)
            (shared / 'run.json').write_text(json.dumps(run))
        run = json.loads((shared / 'run.json').read_text())
    assert run['returncode'] == 0, run['stdout'][-4000:] + run['stderr'][-4000:]
    with open(output / 'summary.json') as f:
        summary = json.load(f)
    return dict(output=output, stdout=run['stdout'],
                phases={row['name']: row for row in summary['phases']},
                in_sim={row['name']: row for row in summary['in_sim_phases']})


def test_every_output_is_written(tutorial):
    for name in OUTPUTS:
        path = tutorial['output'] / name
        assert path.is_file() and path.stat().st_size > 0, name


def test_the_output_folder_holds_this_runs_outputs_only(tutorial):
    assert set(os.listdir(tutorial['output'])) == set(OUTPUTS) | {'logs'}
    # A later run clears every one of them before it writes.
    assert set(OUTPUTS) <= set(job_outputs())


def test_each_phase_is_announced(tutorial):
    for command in ('pos_cmd std_msgs/Float64 1.0', 'pos_cmd std_msgs/Float64 2.0',
                    'pos_cmd std_msgs/Float64 0.0', 'spawn_model -database cafe_table',
                    'pos_cmd std_msgs/Float64 2.5',
                    'roslaunch minimal_robot_description minimal_robot_in_sim_w_jnt_ctl.launch',
                    'rostopic pub /one_DOF_robot/joint1_position_controller/command '
                    'std_msgs/Float64 2.5'):
        assert command in tutorial['stdout']


@pytest.mark.parametrize('name,command', [('command_1.0', 1.0), ('command_2.0', 2.0)])
def test_link_droops_past_the_command_where_gravity_balances_the_gain(tutorial, name, command):
    phase = tutorial['phases'][name]
    expected = physics.settled_angle(command)
    assert expected > command
    assert phase['settled'] == pytest.approx(expected, abs=1e-4)
    # The held torque cancels gravity's m g d sin q.
    assert -phase['holding_torque'] == pytest.approx(physics.gravity_torque(phase['settled']),
                                                     rel=1e-3)


def test_step_to_two_overshoots(tutorial):
    assert tutorial['phases']['command_2.0']['overshoot'] > 0.01


def test_upright_is_held(tutorial):
    assert tutorial['phases']['upright_0.0']['settled'] == pytest.approx(0.0, abs=1e-3)


def test_link_rests_on_the_table_pressing_with_the_remaining_error(tutorial):
    phase = tutorial['phases']['table_2.5']
    assert phase['settled'] == pytest.approx(physics.table_contact_angle(0.85), abs=0.02)
    assert phase['holding_torque'] == pytest.approx(physics.KP * (2.5 - phase['settled']),
                                                    rel=0.02)


@pytest.mark.parametrize('name,command', [('command_1.0', 1.0), ('command_2.0', 2.0),
                                          ('upright_0.0', 0.0)])
def test_in_sim_pid_settles_at_the_command(tutorial, name, command):
    phase = tutorial['in_sim'][name]
    # The integral term removes the P-D droop the rospy controller shows in the same phase.
    assert phase['settled'] == pytest.approx(command, abs=1e-3)
    assert phase['holding_torque'] == pytest.approx(phase['predicted_torque'], abs=0.01)
    if command:
        assert abs(tutorial['phases'][name]['settled'] - command) > 0.3


def test_in_sim_pid_rests_on_the_table_pressing_with_error_and_clamped_integral(tutorial):
    phase = tutorial['in_sim']['table_2.5']
    assert phase['settled'] == pytest.approx(physics.table_contact_angle(0.85), abs=0.02)
    # p (c - q) plus the integral term at its clamp (i_clamp_max 10).
    assert phase['holding_torque'] == pytest.approx(10.0 * (2.5 - phase['settled']) + 10.0,
                                                    rel=0.02)


def in_process_settled_angles(engine):
    """The settled angle of each phase of the tutorial run in-process, with no ROS between the
    controller law and the engine (the cross-validation's run)."""
    from onedof_sim.reference.cross_validation import ToolEngine, settled
    from onedof_sim.tutorial.phases import PHASES
    run = ToolEngine(engine).scenario(PHASE_DURATION)
    return {phase.name: settled(run, index, PHASE_DURATION) for index, phase in enumerate(PHASES)}


def test_settled_angles_are_the_in_process_runs(tutorial):
    expected = in_process_settled_angles('ode')
    for name, phase in tutorial['phases'].items():
        assert abs(phase['settled'] - expected[name]) < SAME, (name, phase['settled'],
                                                               expected[name])
        assert phase['samples'] == round(PHASE_DURATION * 100), name


def test_figures_are_the_same_with_a_busy_process_per_core_beside_it(tutorial, tmp_path):
    # The lock-stepped phases of the rospy controller: the in-sim PID's run takes no part in
    # lock-step (it steps a paused world, the controller inside the step) and would double this
    # run's time; the player checks in every run that each of its steps ran on the command.
    with busy_processes(BUSY_PROCESSES):
        loaded = play_tutorial(tmp_path / 'loaded', '--no-screenshot', '--no-figures',
                               '--in-sim-phase-duration', '0')
    assert loaded['returncode'] == 0, loaded['stdout'][-4000:] + loaded['stderr'][-4000:]
    # The figures are the summary's: --no-figures leaves out only the plots.
    assert not list((tmp_path / 'loaded').glob('*.png'))
    with open(tmp_path / 'loaded' / 'summary.json') as f:
        phases = {row['name']: row for row in json.load(f)['phases']}
    for name, phase in tutorial['phases'].items():
        assert abs(phases[name]['settled'] - phase['settled']) < SAME, name
    # Not only close: the same run, figure for figure.
    assert phases == tutorial['phases']


def count_pixels(png, region, predicate):
    """Pixels of region (x0, y0, x1, y1) whose 8-bit (r, g, b) satisfy the predicate."""
    import matplotlib.image
    rgb = (matplotlib.image.imread(str(png))[..., :3] * 255).round()
    x0, y0, x1, y1 = region
    r, g, b = (rgb[y0:y1, x0:x1, i] for i in range(3))
    return int(predicate(r, g, b).sum())


# Where things are in the screenshot: rviz in a 1000 x 720 Xvfb screen with the committed view
# (camera on -y looking at the x-z plane where the link swings; +x to the right). The robot is
# rviz's default red; link1 stands left of x = 620, so red right of it is link2 reaching toward the
# table, and grey below link2's height there is the table's column and base.
RIGHT_OF_LINK1_ABOVE_TABLE = (640, 62, 984, 370)
UNDER_THE_TABLE_TOP = (640, 390, 984, 690)
robot_red = lambda r, g, b: (r > 170) & (g < 90) & (b < 90)
marker_grey = lambda r, g, b: (abs(r - g) < 12) & (abs(g - b) < 12) & (r > 110) & (r < 230)


def test_rviz_screenshot_shows_link2_on_the_table(tutorial):
    png = tutorial['output'] / 'rviz_final.png'
    assert count_pixels(png, RIGHT_OF_LINK1_ABOVE_TABLE, robot_red) > 500, \
        'no robot-red pixels where link2 should rest, right of link1'
    assert count_pixels(png, UNDER_THE_TABLE_TOP, marker_grey) > 300, \
        'no table markers under the table top'
    all_pixels = (0, 0, 1000, 720)
    assert count_pixels(png, all_pixels, lambda r, g, b: r >= 0) > \
        count_pixels(png, all_pixels, lambda r, g, b: (r == 48) & (g == 48) & (b == 48)) * 1.2, \
        'the picture is mostly rviz background'
