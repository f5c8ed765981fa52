"""The Gazebo panel of rviz (src/gazebo_ros_panels), against the real simulator: the panel's
actions (gazebo_panel_actions runs the GazeboClient calls its buttons make) pause, step and play
the world, insert copies named name_0, name_1, list what the model path holds when asked, list
the models' links and joints, move a model and set the physics, and say why when there is no
simulator or the simulator refuses; and the simulator's rviz view (gzclient) loads the panel,
whose buttons, pressed with xdotool through their Alt mnemonics, pause and play the world and
insert cafe_table_0 then cafe_table_1, at a typed position or where a click in the 3D view falls."""
import math
import re
import subprocess

import pytest
import yaml

from api_client import ROBOT, GazeboApi
from conftest import ENGINES, GROUND, start_sim
from gazebo_commands import output, run
from onedof_sim.tutorial.rviz_view import start_xvfb
from test_rviz_sensors import WORLD_RVIZ, project

PANEL_UP = 'gazebo_ros_panels: the Gazebo panel is up'


def actions(ros, *args, env=None):
    return run(ros, 'rosrun', 'gazebo_ros_panels', 'gazebo_panel_actions', *args, env=env,
               timeout=300)


def model_names(api):
    """The models inserted: the world's, but for the ground_plane its world file places."""
    return sorted(name for name in api.get_world_properties().model_names if name != GROUND)


def write_model(folder, name, shown_name, sdf):
    model = folder / name
    model.mkdir(parents=True)
    (model / 'model.config').write_text(
        '<model><name>%s</name><sdf version="1.6">model.sdf</sdf></model>' % shown_name)
    (model / 'model.sdf').write_text(sdf)


def test_pause_step_and_play(ros, rospy_client, engine):
    start_sim(ros, engine)
    api = GazeboApi(rospy_client)
    assert not api.get_physics_properties().pause
    result = actions(ros, 'pause')
    assert result.returncode == 0 and result.stdout == 'paused\n', output(result)
    assert api.get_physics_properties().pause
    before = api.get_world_properties().sim_time
    result = actions(ros, 'step', '10')
    assert result.returncode == 0, output(result)
    assert 'stepped 10 steps' in result.stdout
    step = api.get_physics_properties().time_step
    assert api.get_world_properties().sim_time == pytest.approx(before + 10 * step, abs=1e-9)
    assert api.get_physics_properties().pause
    result = actions(ros, 'unpause')
    assert result.returncode == 0 and result.stdout == 'running\n', output(result)
    assert not api.get_physics_properties().pause


def test_insert_names_copies_and_lists_the_model_path(ros, rospy_client, engine, tmp_path):
    start_sim(ros, engine, env={'GAZEBO_MODEL_PATH': str(tmp_path)})
    api = GazeboApi(rospy_client)
    catalog = actions(ros, 'catalog', env={'GAZEBO_MODEL_PATH': str(tmp_path)})
    assert catalog.returncode == 0, output(catalog)
    listed = dict(line.split('\t') for line in catalog.stdout.splitlines())
    assert listed['cafe_table'] == 'Cafe table' and listed['unit_box'] == 'Box'
    assert 'late_block' not in listed
    # A model added to the path is listed the next time the path is read, and inserts.
    write_model(tmp_path, 'late_block', 'Late block',
                '<sdf version="1.6"><model name="late_block"><static>true</static>'
                '<link name="link"><collision name="c"><geometry><box><size>0.2 0.2 0.2</size>'
                '</box></geometry></collision></link></model></sdf>')
    catalog = actions(ros, 'catalog', env={'GAZEBO_MODEL_PATH': str(tmp_path)})
    assert 'late_block\tLate block' in catalog.stdout.splitlines(), output(catalog)

    for expected in ('cafe_table_0', 'cafe_table_1'):
        result = actions(ros, 'insert', 'cafe_table', '1.0', '0.5', '0')
        assert result.returncode == 0 and result.stdout == 'inserted %s\n' % expected, \
            output(result)
    assert model_names(api) == ['cafe_table_0', 'cafe_table_1']
    position = api.get_model_state('cafe_table_1', '').pose.position
    assert (position.x, position.y, position.z) == pytest.approx((1.0, 0.5, 0.0))
    result = actions(ros, 'insert', 'unit_box', '-1', '0', '0')
    assert result.returncode == 0 and result.stdout == 'inserted unit_box_0\n', output(result)
    result = actions(ros, 'insert', 'late_block', '0', '-1', '0',
                     env={'GAZEBO_MODEL_PATH': str(tmp_path)})
    assert result.returncode == 0 and result.stdout == 'inserted late_block_0\n', output(result)
    assert model_names(api) == ['cafe_table_0', 'cafe_table_1', 'late_block_0', 'unit_box_0']


def test_a_refused_insert_shows_the_simulators_reason(ros, rospy_client, tmp_path):
    start_sim(ros, ENGINES[0], env={'GAZEBO_MODEL_PATH': str(tmp_path)})
    api = GazeboApi(rospy_client)
    write_model(tmp_path, 'broken', 'Broken', '<sdf version="1.6"><model name="broken">')
    result = actions(ros, 'insert', 'broken', '0', '0', '0',
                     env={'GAZEBO_MODEL_PATH': str(tmp_path)})
    assert result.returncode == 1, output(result)
    assert result.stdout.startswith('broken_0: '), output(result)
    reason = result.stdout[len('broken_0: '):].strip()
    assert reason, output(result)
    assert model_names(api) == []


def test_without_a_simulator_the_panel_says_so(ros):
    for action in ('pause', 'unpause', 'reset_world', 'reset_time'):
        result = actions(ros, action)
        assert result.returncode == 1, output(result)
    assert result.stdout == 'no simulator: /gazebo/reset_simulation is not served\n', \
        output(result)
    result = actions(ros, 'step', '1')
    assert result.returncode == 1 and 'is not served' in result.stdout, output(result)


def xdotool(display, *args):
    return subprocess.run(['xdotool'] + list(args), env={'DISPLAY': display},
                          capture_output=True, text=True, timeout=60)


def press(display, window, keys):
    """Focuses rviz's window and types keys (xdotool's names) into it."""
    focused = xdotool(display, 'windowfocus', '--sync', window)
    assert focused.returncode == 0, focused.stderr
    typed = xdotool(display, 'key', '--clearmodifiers', *keys)
    assert typed.returncode == 0, typed.stderr


def start_gzclient(ros):
    """gzclient (rviz on the world view) on an Xvfb of its own, once its Gazebo panel has listed
    the model path; (its process, the display, rviz's window id)."""
    _, display = start_xvfb(ros)
    gzclient = ros.start(['rosrun', 'gazebo_ros', 'gzclient'], name='gzclient',
                         env={'DISPLAY': display, 'LIBGL_ALWAYS_SOFTWARE': '1'})
    ros.wait_until(lambda: PANEL_UP in ros.log_text(gzclient), 300, what='the Gazebo panel')
    ros.wait_until(lambda: 'gazebo_ros_panels: Insert: ' in ros.log_text(gzclient), 300,
                   what='the panel to list the model path')
    window = ros.wait_until(
        lambda: xdotool(display, 'search', '--onlyvisible', '--name', 'RViz').stdout.split(),
        120, what="rviz's window")[0]
    return gzclient, display, window


def test_gzclient_shows_the_panel_whose_buttons_drive_the_world(ros, rospy_client):
    start_sim(ros, ENGINES[0])
    api = GazeboApi(rospy_client)
    gzclient, display, window = start_gzclient(ros)
    log = ros.log_text(gzclient)
    assert 'PluginlibFactory' not in log and 'Failed to load' not in log, log

    # Pause (Alt+U), then Play (Alt+A) once the panel shows the world paused.
    press(display, window, ['alt+u'])
    ros.wait_until(lambda: api.get_physics_properties().pause, 60, what='the world paused')

    # Alt+A is Play's only once the panel has seen the pause (it asks each second): pressed until
    # the world plays; pressed again after that it does nothing (the button says Pause).
    def played():
        press(display, window, ['alt+a'])
        try:
            return ros.wait_until(lambda: not api.get_physics_properties().pause, 3,
                                  what='the world playing')
        except TimeoutError:
            return False
    ros.wait_until(played, 120, what='the world playing again')

    # Insert tab (Alt+I), its model list (Alt+D), "Cafe table" chosen by typing, Insert (Alt+N).
    press(display, window, ['alt+i', 'alt+d', 'C', 'a', 'f', 'e'])
    for expected in ('cafe_table_0', 'cafe_table_1'):
        press(display, window, ['alt+n'])
        ros.wait_until(lambda: expected in model_names(api), 60, what=expected)
    assert model_names(api) == ['cafe_table_0', 'cafe_table_1']
    # The panel says what it did (its reply may come after the model shows in the world).
    ros.wait_until(lambda: 'gazebo_ros_panels: inserted cafe_table_1' in ros.log_text(gzclient),
                   60, what="the panel's report of the second insert")
    assert gzclient.poll() is None, ros.log_text(gzclient)


def render_window(display):
    """(x, y, width, height) of rviz's 3D view on the screen: the one unnamed native window
    under rviz's main window (Ogre's), as xwininfo lists it."""
    tree = subprocess.run(['xwininfo', '-root', '-tree'], env={'DISPLAY': display},
                          capture_output=True, text=True, timeout=60).stdout
    views = [tuple(int(v) for v in match.groups()) for match in re.finditer(
        r'\(has no name\): \(\)\s+(\d+)x(\d+)\+-?\d+\+-?\d+\s+\+(-?\d+)\+(-?\d+)', tree)]
    views = [(x, y, w, h) for w, h, x, y in views if w > 100 and h > 100]
    return views[0] if len(views) == 1 else None


def pixel_of(point, window):
    """The screen pixel where world.rviz's view draws a point of the world, in rviz's 3D view
    at window (x, y, width, height)."""
    with open(WORLD_RVIZ) as f:
        view = yaml.safe_load(f)['Visualization Manager']['Views']['Current']
    x, y, width, height = window
    column, row = project(view, (x, y, x + width, y + height), point)
    return round(column), round(row)


def test_a_click_in_the_view_inserts_the_chosen_model_there(ros, rospy_client):
    start_sim(ros, ENGINES[0])
    api = GazeboApi(rospy_client)
    gzclient, display, window = start_gzclient(ros)
    view = ros.wait_until(lambda: render_window(display), 120, what="rviz's 3D view")
    waiting = 'gazebo_ros_panels: click in the 3D view where Cafe table goes'
    targets = (('cafe_table_0', (1.0, 0.5, 0.0)), ('cafe_table_1', (-1.0, 1.0, 0.0)))
    for count, (expected, target) in enumerate(targets, 1):
        # Insert tab, its list, "Cafe table" typed, Insert by clicking (Alt+C), then the click.
        press(display, window, ['alt+i', 'alt+d', 'C', 'a', 'f', 'e', 'alt+c'])
        ros.wait_until(lambda: ros.log_text(gzclient).count(waiting) == count, 60,
                       what='the panel to wait for a click')
        x, y = pixel_of(target, view)
        clicked = xdotool(display, 'mousemove', '--sync', str(x), str(y), 'click', '1')
        assert clicked.returncode == 0, clicked.stderr
        ros.wait_until(lambda: expected in model_names(api), 60, what=expected)
        position = api.get_model_state(expected, '').pose.position
        assert math.hypot(position.x - target[0], position.y - target[1]) < 0.05, position
        assert abs(position.z) < 0.05, position
    assert gzclient.poll() is None, ros.log_text(gzclient)


def test_world_tab_lists_moves_and_sets_physics(ros, rospy_client, engine):
    start_sim(ros, engine)
    api = GazeboApi(rospy_client)
    api.pause_physics()
    api.spawn_robot()
    result = actions(ros, 'insert', 'unit_box', '0', '0', '0')
    assert result.returncode == 0, output(result)
    tree = actions(ros, 'tree')
    assert tree.returncode == 0, output(tree)
    rows = {line.split('\t')[0]: line.split('\t')[1:] for line in tree.stdout.splitlines()}
    assert rows['unit_box_0'] == ['link', '']
    properties = api.get_model_properties(ROBOT)
    assert properties.joint_names
    assert rows[ROBOT] == [','.join(properties.body_names), ','.join(properties.joint_names)]

    result = actions(ros, 'move', 'unit_box_0', '2', '1', '0.5')
    assert result.returncode == 0 and result.stdout == 'moved unit_box_0\n', output(result)
    position = api.get_model_state('unit_box_0', '').pose.position
    assert (position.x, position.y, position.z) == pytest.approx((2, 1, 0.5))
    result = actions(ros, 'move', 'no_such_model', '0', '0', '0')
    assert result.returncode == 1 and result.stdout.startswith('no_such_model: '), output(result)

    before = api.get_physics_properties()
    result = actions(ros, 'set_physics', '0.002', '250', '0', '0', '-5')
    assert result.returncode == 0 and result.stdout == 'physics set\n', output(result)
    after = api.get_physics_properties()
    assert (after.time_step, after.max_update_rate) == (0.002, 250)
    assert (after.gravity.x, after.gravity.y, after.gravity.z) == (0, 0, -5)
    assert after.ode_config == before.ode_config
    shown = actions(ros, 'physics')
    assert shown.stdout == 'paused 1 step 0.002 max_update_rate 250 gravity 0 0 -5\n', \
        output(shown)
