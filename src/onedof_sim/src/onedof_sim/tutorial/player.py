"""The main job: plays the tutorial headless on a private ROS graph and writes what a student would
look at. The steps are the tutorial's: launch the simulator with the robot, run the controller,
command 1.0 then 2.0, bring the arm upright (0), insert the cafe table at x = 0.85, command 2.5.
With gui_table the simulator's window (gzclient) is open throughout, and the table goes in as the
tutorial's student puts it: inserted through the window's Insert tab by a click on the ground,
then dragged to x = 0.85 by its handle's arrow with the mouse (gazebo_window), a screenshot of
the window after each step.
Each phase lasts a fixed span of sim time; the recorder keeps every sample for the plots, the CSV
and the per-phase figures.

By default the simulator runs in lock-step with the controller (it waits for the controller's
command at the end of every period) and the player advances it phase by phase with
/gazebo/step_simulation (which a lock-stepped simulator serves), each command taken before its
phase starts: the figures are the physics' alone, the same on every run however busy the
machine. The controller's first period
runs on its initial command 0, before the player has commanded anything, and it starts after one
period of the arm at rest (sim time 0 is no valid time to a ROS node): the phases start at
0.02 s. With free_run the simulator paces itself at a real-time factor and the controller samples
it over the network as a real robot would be, missed periods included.

Then the same phases play again through the in-simulator PID (the book's gazebo_ros_control
robot and YAML, effort_controllers/JointPositionController), on a paused world stepped phase by
phase, and each phase's figure shows both controllers (what the integral term does to the droop).

This module orchestrates the job (play, and the in-sim run in a process of its own) and keeps its
outputs (what it writes, clears and reports missing). Beside it: phases (what is played),
recorders (what is recorded), runs (how the simulator is advanced through the phases), summary
(the figures of each phase), rviz_view (the screenshot), and physics (the closed forms and the
predictions).
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

from onedof_harness.private_ros import PrivateRos
from onedof_harness.rospy_shutdown import shut_down_rospy
from onedof_sim.tutorial.gazebo_window import WINDOW_SHOTS, GazeboWindow, place_table_by_mouse
from onedof_sim.tutorial.phases import CONTROL_PERIOD, PHASES, with_table_at
from onedof_sim.tutorial.physics import pid_prediction
from onedof_sim.tutorial.recorders import JointStatesRecorder, Recorder
from onedof_sim.tutorial.runs import (IN_SIM_COMMAND, IN_SIM_PHASE_DURATION, IN_SIM_SAMPLE_PERIOD,
                                      FreeRun, InSimRun, LockstepRun, book_pid_gains, play_phases,
                                      run_before, say)
from onedof_sim.tutorial.rviz_view import RvizView
from onedof_sim.tutorial.summary import summary_markdown

DEFAULT_TIME_STEP = 0.001  # the simulators' default step, s
# Wall seconds the lock-stepped simulator waits for a silent controller: far beyond any period's
# work on a loaded machine, so that it never gives up on a live controller; a dead one is
# noticed by its exit.
LOCKSTEP_TIMEOUT = 30


# Every file the job writes into its output folder, beside logs/ (for every phase, whichever
# phases a run plays): what a run removes before it writes, so that nothing of an earlier run
# stays beside its outputs, and nothing else of a folder the user named.
SCREENSHOT = 'rviz_final.png'
WHOLE_RUN_OUTPUTS = ('tutorial.png', 'samples.csv', SCREENSHOT, 'summary.md', 'summary.json',
                     'in_sim_samples.csv') + WINDOW_SHOTS
PHASE_OUTPUTS = ('phase%d_%s.png', 'phase%d_%s_pd_vs_pid.png')


def job_outputs():
    return list(WHOLE_RUN_OUTPUTS) + [pattern % (number, phase.name) for pattern in PHASE_OUTPUTS
                                      for number, phase in enumerate(PHASES, 1)]


def clear_outputs(output):
    """Removes from `output` what a run of the job writes there (job_outputs() and logs/),
    nothing else: the folder may be the user's own."""
    for name in job_outputs():
        try:
            os.remove(os.path.join(output, name))
        except FileNotFoundError:
            pass
    shutil.rmtree(os.path.join(output, 'logs'), ignore_errors=True)


class MissingOutputs(RuntimeError):
    """The run wrote every output but these: {name: why it is missing}."""

    def __init__(self, missing):
        self.missing = missing
        super().__init__('; '.join('%s is missing: %s' % item for item in missing.items()))


def play_in_sim(log_dir, physics_engine, phase_duration=IN_SIM_PHASE_DURATION, phases=PHASES):
    """The tutorial's phases through the in-simulator PID, launched as the book does it (our
    minimal_robot_in_sim_w_jnt_ctl.launch: the simulator, the robot with gazebo_ros_control's tag,
    the book's YAML and the spawner), paused and stepped. Runs in a process of its own (rospy
    inits once per process). Returns (rows, [per-phase series since each command], the whole
    run's series)."""
    with PrivateRos(log_dir=log_dir, use_sim_time=True) as ros:
        launch = ['roslaunch', 'minimal_robot_description', 'minimal_robot_in_sim_w_jnt_ctl.launch',
                  'physics:=' + physics_engine, 'paused:=true', 'enable_step_simulation:=true']
        say(' '.join(launch))
        ros.start(launch, name='launch_in_sim')
        ros.adopt_environment()
        import rospy
        rospy.init_node('tutorial_player', disable_signals=True)
        recorder = Recorder()
        ros.wait_for_service('/gazebo/get_physics_properties', timeout=60)
        run = InSimRun(ros, rospy, recorder)
        run.wait_for_controllers()
        predict = pid_prediction(book_pid_gains())
        rows, series, _ = play_phases(ros, run, recorder, phases, phase_duration,
                                      IN_SIM_COMMAND, IN_SIM_SAMPLE_PERIOD, predict)
        shut_down_rospy(rospy, 'in-sim tutorial finished')
    return rows, series, recorder.series()


def compared_panels(pd_series, pid_series):
    """One figure's panels [(ylabel, {label: (times, values)})]: the command and each controller's
    position above, each controller's torque below, labelled by controller, each panel by its
    unit (plot.unit_panels)."""
    from onedof_sim.tools import plot
    labelled = (('rospy PD', pd_series), ('in-sim PID', pid_series))
    # The controllers first in both panels: each keeps its colour from one panel to the other.
    series = {'%s jnt_pos' % label: data['jnt_pos'] for label, data in labelled}
    series['pos_cmd'] = pid_series['pos_cmd']
    series.update(('%s jnt_trq' % label, data['jnt_trq']) for label, data in labelled)
    return plot.unit_panels(series)


def play_in_sim_beside(output, physics_engine, phase_duration, phases, pd_rows, pd_series,
                       pd_phase_duration, figures=True):
    """Plays the phases through the in-simulator PID (in a process of its own: this one's rospy
    belongs to the first graph; see in_sim_main) and (with figures) draws each phase's figure
    beside the rospy PD controller's; writes in_sim_samples.csv; returns the in-sim rows."""
    from onedof_sim.tools import plot
    result_path = os.path.join(output, 'logs', 'in_sim', 'result.json')
    os.makedirs(os.path.dirname(result_path), exist_ok=True)
    # A process of our Python started as play_tutorial is: the same imports (onedof_sim's
    # generated messages with it), its own rospy node, its log lines on our output.
    table = next((phase.table for phase in phases if phase.table), (0.0, 0.0, 0.0))
    subprocess.run([sys.executable, '-m', 'onedof_sim.tutorial.player', result_path,
                    physics_engine, repr(phase_duration), str(len(phases))] +
                   [repr(v) for v in table], check=False)
    try:
        with open(result_path) as f:
            result = json.load(f)
    except (OSError, ValueError) as error:
        raise RuntimeError('the in-sim run left no result (%s)' % error) from None
    if 'error' in result:
        raise RuntimeError('in-sim run: ' + result['error'])
    rows, series, whole = result['rows'], result['series'], result['whole']
    drawn = zip(phases, pd_rows, pd_series, series) if figures else ()
    for number, (phase, pd_row, pd, pid) in enumerate(drawn, 1):
        plot.write_panels_figure(
            compared_panels(pd, pid),
            os.path.join(output, 'phase%d_%s_pd_vs_pid.png' % (number, phase.name)),
            title='%s (%s): rospy PD settles at %.3f, in-sim PID at %.3f'
                  % (phase.name, physics_engine, pd_row['settled'], rows[number - 1]['settled']),
            xlabel='sim time since the command (s); the rospy PD\'s phase ends at %g s, its '
                   'last values drawn held after' % pd_phase_duration, until=phase_duration,
            zoom=True)
    plot.write_csv(whole, os.path.join(output, 'in_sim_samples.csv'))
    return rows


def in_sim_main(argv):
    """`python -m onedof_sim.tutorial.player RESULT_JSON PHYSICS DURATION PHASES TABLE_X TABLE_Y
    TABLE_Z`: play_in_sim of the first PHASES phases, the table at (TABLE_X, TABLE_Y, TABLE_Z),
    its logs beside RESULT_JSON, its rows and series (or the error) into it."""
    result_path, physics_engine, phase_duration, phase_count = argv[:4]
    phases = with_table_at(PHASES[:int(phase_count)], *(float(v) for v in argv[4:]))
    try:
        rows, series, whole = play_in_sim(os.path.dirname(result_path), physics_engine,
                                          float(phase_duration), phases)
        result = dict(rows=rows, series=series, whole=whole)
    except (RuntimeError, TimeoutError) as error:
        result = dict(error=str(error))
    with open(result_path, 'w') as f:
        json.dump(result, f)


def play(output, physics_engine, phase_duration=5.0, screenshot=True, free_run=False,
         real_time_factor=1.0, phases=PHASES, in_sim_phase_duration=IN_SIM_PHASE_DURATION,
         figures=True, gui_table=False):
    """Plays the tutorial's `phases` (a leading part of PHASES, or of with_table_at(PHASES, ...):
    each starts where the one before left the arm), in lock-step unless free_run (then paced at
    real_time_factor), then (unless in_sim_phase_duration is 0) the same phases through the
    in-simulator PID; returns the rospy controller's per-phase summary rows; without figures it
    draws no plot (for a caller that reads the summary alone). With gui_table the table goes in
    through the simulator's window (see the module's doc; its screenshots replace the rviz
    screenshot), and the phases after it play with the table where the mouse left it. Starts by
    clearing what an earlier run wrote into `output` (clear_outputs). Raises with the reason on
    failure; raises MissingOutputs after writing every other output when the rviz screenshot
    could not be taken."""
    from onedof_sim.tools import plot
    os.makedirs(output, exist_ok=True)
    clear_outputs(output)
    log_dir = os.path.join(output, 'logs')
    missing = {}  # {output name: why it is missing}
    wall_start = time.monotonic()
    # /use_sim_time before any node starts, as Gazebo's launch files do, so that every node
    # (this one included) runs on sim time from its first message.
    with PrivateRos(log_dir=log_dir, use_sim_time=True) as ros:
        say('roscore on %s (logs in %s)' % (ros.master_uri, log_dir))
        # Paused until the controller runs: the upright pose is an unstable balance, which one
        # engine holds exactly and the other loses to round-off before a late controller starts.
        launch = ['roslaunch', 'minimal_robot_description', 'minimal_robot_description.launch',
                  'physics:=' + physics_engine, 'paused:=true']
        if free_run:
            if real_time_factor != 1.0:
                launch.append('max_update_rate:=%g' % (real_time_factor / DEFAULT_TIME_STEP))
        else:
            launch += ['lockstep:=true', 'lockstep_timeout:=%g' % LOCKSTEP_TIMEOUT]
        say(' '.join(launch))
        ros.start(launch, name='launch_simulator')
        ros.adopt_environment()
        import rospy
        rospy.init_node('tutorial_player', disable_signals=True)
        from gazebo_msgs.srv import GetModelState
        ros.wait_for_service('/gazebo/get_model_state', timeout=60)
        model_state = rospy.ServiceProxy('/gazebo/get_model_state', GetModelState)
        ros.wait_until(lambda: model_state('one_DOF_robot', '').success, 60,
                       what='one_DOF_robot to be spawned')
        # rviz (software rendering) starts while the simulator is paused and is up before the
        # phases run, so its start-up never takes the CPU from the controller.
        # rviz may die (see rviz_view): the view restarts it, and the job goes on without it.
        rviz = window = None
        if gui_table:
            window = GazeboWindow(ros, say)
            window.screenshot(os.path.join(output, WINDOW_SHOTS[0]))
        elif screenshot:
            rviz = RvizView(ros, tempfile.mkdtemp(prefix='tutorial_rviz_'), say)
            rviz.wait_until_up()
        from std_msgs.msg import Float64
        pos_cmd = rospy.Publisher('/pos_cmd', Float64, queue_size=1, latch=True)
        recorder = JointStatesRecorder(rospy)
        run = (FreeRun if free_run else LockstepRun)(ros, rospy, recorder, pos_cmd)
        run.before_controller()
        say('rosrun minimal_joint_controller minimal_joint_controller')
        ros.start(['rosrun', 'minimal_joint_controller', 'minimal_joint_controller'],
                  name='controller')
        # Paused, sim time stands still: wait for the controller's topics before it runs.
        ros.wait_until(lambda: recorder.connected() and pos_cmd.get_num_connections() > 0, 60,
                   what='the controller to publish joint_states and subscribe pos_cmd')
        run.start()
        played = list(phases)  # the phases as played: the table where the mouse left it

        def place_table(ros, phase):
            if window and phase.table:
                _, placed = place_table_by_mouse(window, rospy, phase.table[0], output)
                played[played.index(phase)] = phase = phase._replace(table=placed)
                return phase
            return run_before(ros, phase)
        rows, pd_series, spans = play_phases(
            ros, run, recorder, phases, phase_duration, 'pos_cmd',
            sample_period=None if free_run else CONTROL_PERIOD, before=place_table)
        phases = tuple(played)
        drawn = zip(phases, pd_series, spans) if figures else ()
        for number, (phase, series, (start, end)) in enumerate(drawn, 1):
            plot.write_figure(
                series, os.path.join(output, 'phase%d_%s.png' % (number, phase.name)),
                title='%s: pos_cmd %.1f (%s)' % (phase.name, phase.command, physics_engine),
                xlabel='sim time since the command (s)', until=end - start)
        # From the first command on: whether the controller's first sample (its period on the
        # initial command 0) reaches us depends on how soon our subscription connects.
        t0, end = spans[0][0], spans[-1][1]
        whole = recorder.series(start=t0, origin=t0)
        plot.write_csv(whole, os.path.join(output, 'samples.csv'))
        if figures:
            plot.write_figure(whole, os.path.join(output, 'tutorial.png'),
                              title='The whole tutorial (%s)' % physics_engine,
                              xlabel='sim time (s)', until=end - t0)
        if window:
            say('the window at the final pose')
            window.screenshot(os.path.join(output, WINDOW_SHOTS[-1]))
            window.stop()
        if rviz:
            say('rviz screenshot of the final pose (the table from the collision markers)')
            why = rviz.screenshot(os.path.join(output, SCREENSHOT), refresh=run.refresh)
            rviz.stop()
            if why:
                missing[SCREENSHOT] = why
        # The in-sim run and the figures follow in this process.
        shut_down_rospy(rospy, 'tutorial finished')
    in_sim_rows = []
    if in_sim_phase_duration:
        in_sim_rows = play_in_sim_beside(output, physics_engine, in_sim_phase_duration, phases,
                                         rows, pd_series, phase_duration, figures)
    summary = summary_markdown(rows, physics_engine, free_run, in_sim_rows)
    with open(os.path.join(output, 'summary.md'), 'w') as f:
        f.write(summary)
    with open(os.path.join(output, 'summary.json'), 'w') as f:
        json.dump({'physics': physics_engine, 'lockstep': not free_run, 'phases': rows,
                   'in_sim_phases': in_sim_rows,
                   'table': next((list(phase.table) for phase in phases if phase.table), None)},
                  f, indent=1)
    print(summary)
    say('done in %.1f s of wall time; outputs in %s' % (time.monotonic() - wall_start, output))
    if missing:
        for name, why in missing.items():
            say('%s is missing: %s' % (name, why))
        raise MissingOutputs(missing)
    return rows


if __name__ == '__main__':
    in_sim_main(sys.argv[1:])
