"""gzserver, gzclient and gazebo as this workspace runs them: onedof_sim, this workspace's simulator,
stands in for Gazebo's server (with gzserver's arguments, passed through), and rviz showing the
simulated world stands in for Gazebo's GUI.

Each program says so in one line when it starts, and in -h.
"""
import os
import signal
import subprocess
import sys

SERVER = ['rosrun', 'onedof_sim', 'onedof_sim']
GUI_INSTEAD = ("no Gazebo GUI in this workspace; instead rviz shows the simulated world "
               "(its models' visuals, /gazebo/visual_markers, and the scans, point clouds and images of the "
               "robots' sensors; the robot too: roslaunch minimal_robot_description "
               "display.launch)")
SERVER_HELP = """usage: {prog} [-u|--pause] [-e ENGINE] [WORLD_FILE] [_param:=value ...]

onedof_sim, this workspace's simulator, standing in for Gazebo's gzserver: the node `gazebo`
serving Gazebo's ROS API under /gazebo/ (rosrun onedof_sim onedof_sim with these arguments).

  -u, --pause   start paused
  -e ENGINE     physics engine, one of: rosrun onedof_sim onedof_sim --list-physics
  WORLD_FILE    an SDF world: its physics, gravity, models and model:// includes
                (GAZEBO_MODEL_PATH); lights, scene, GUI and world plugins are said to be ignored;
                default: the empty world. Any other gzserver flag is ignored with a warning
  _name:=value  the node's parameters (src/onedof_sim/README.md), e.g. _max_update_rate:=0
"""


def _server_command(argv):
    """SERVER with argv, its executable started by path: through rosrun each start would cost
    another shell and catkin_find process (0.15 CPU-s) before the node runs. Not found, rosrun
    runs and says so."""
    from onedof_sim.tools import rosrun_by_path
    try:
        return rosrun_by_path(SERVER) + argv
    except RuntimeError:
        return SERVER + argv


def _gui_command():
    """The world view (gazebo_ros.world_view) in a process of its own."""
    return [sys.executable, '-m', 'gazebo_ros.world_view']


def _has_display():
    return bool(os.environ.get('DISPLAY'))


def _wants_help(argv):
    return any(arg in ('-h', '--help') for arg in argv)


def _say(prog, text):
    print('%s: %s' % (prog, text), flush=True)


def _server_line(argv):
    return ("onedof_sim, this workspace's simulator, standing in for Gazebo's gzserver: %s"
            % ' '.join(SERVER + argv))


def gzserver_main(argv):
    if _wants_help(argv):
        print(SERVER_HELP.format(prog='gzserver'), end='')
        return 0
    _say('gzserver', _server_line(argv))
    command = _server_command(argv)
    os.execvp(command[0], command)


def gzclient_main(argv):
    if _wants_help(argv):
        print('usage: gzclient\n\n%s.\nStarts it when there is a display ($DISPLAY), else says so '
              'and exits 0.' % GUI_INSTEAD[0].upper() + GUI_INSTEAD[1:])
        return 0
    if not _has_display():
        _say('gzclient', GUI_INSTEAD + ': not started, there is no display ($DISPLAY is unset)')
        return 0
    _say('gzclient', GUI_INSTEAD + ': starting it')
    from gazebo_ros import world_view
    return world_view.main(argv)


def gazebo_main(argv):
    if _wants_help(argv):
        print(SERVER_HELP.format(prog='gazebo'), end='')
        print('\nAnd the GUI: %s, started when there is a display ($DISPLAY).' % GUI_INSTEAD)
        return 0
    if not _has_display():
        _say('gazebo', _server_line(argv) + '; ' + GUI_INSTEAD +
             ': not started, there is no display ($DISPLAY is unset)')
        command = _server_command(argv)
        os.execvp(command[0], command)
    _say('gazebo', _server_line(argv) + '; ' + GUI_INSTEAD + ': starting it')
    server = subprocess.Popen(_server_command(argv))
    gui = subprocess.Popen(_gui_command())

    # Stopping `gazebo` (Ctrl-C, roslaunch's SIGINT then SIGTERM) stops both; closing rviz leaves
    # the simulator running, as the server is what the other nodes need.
    def forward(signum, frame):
        for process in (server, gui):
            if process.poll() is None:
                process.send_signal(signum)

    signal.signal(signal.SIGINT, forward)
    signal.signal(signal.SIGTERM, forward)
    code = server.wait()
    if gui.poll() is None:
        gui.terminate()
        gui.wait()
    return code


def run(main):
    """Entry point of the scripts: main(argv without the program name) as the exit code."""
    sys.exit(main(sys.argv[1:]))
