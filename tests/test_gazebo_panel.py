"""The Gazebo panel of rviz (src/gazebo_ros_panels), against the real simulator: the panel's
actions (gazebo_panel_actions runs the GazeboClient calls its buttons make) pause, step and play
the world, insert copies named name_0, name_1, list what the model path holds when asked, list
the models' links and joints, move a model and set the physics, and say why when there is no
simulator or the simulator refuses; and the simulator's rviz view (gzclient) loads the panel,
whose buttons, pressed with xdotool through their Alt mnemonics, pause and play the world and
insert cafe_table_0 then cafe_table_1, at a typed position or where a click in the 3D view falls;
the window (rviz and its panel) hears the sim time from the simulator's view clock, at the views'
rate, not from /clock at every step, and the panel publishes the frames per second its view
draws."""
import math

import pytest

from api_client import ROBOT, GazeboApi
from conftest import ENGINES, GROUND, start_sim
from gazebo_commands import output, run
from onedof_sim.tutorial.gazebo_window import GazeboWindow


def actions(ros, *args, env=None):
    return run(ros, 'rosrun', 'gazebo_ros_panels', 'gazebo_panel_actions', *args, env=env,
               timeout=300)


def model_names(api):
    """The models inserted: the world's, but for the ground_plane its world file places."""
    return sorted(name for name in api.get_world_properties().model_names if name != GROUND)


def window_subscribers(ros, topic):
    """The nodes of the window (gzclient's rviz) subscribed to `topic`, as the master knows them."""
    _, _, (_, subscriptions, _) = ros.master().getSystemState('/test')
    nodes = next((nodes for name, nodes in subscriptions if name == topic), [])
    return [node for node in nodes if node.startswith('/gzclient')]


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


def test_gzclient_shows_the_panel_whose_buttons_drive_the_world(ros, rospy_client):
    start_sim(ros, ENGINES[0])
    api = GazeboApi(rospy_client)
    window = GazeboWindow(ros)
    log = window.log()
    assert 'PluginlibFactory' not in log and 'Failed to load' not in log, log
    ros.wait_until(lambda: window_subscribers(ros, '/gazebo/view_clock'), 60,
                   what='the window hearing the view clock')
    assert not window_subscribers(ros, '/clock')
    # The view's frames per second, as the Time tab's FPS shows them, each wall second.
    from std_msgs.msg import Float64
    rates = []
    rospy_client.Subscriber('/gazebo_window/frame_rate', Float64,
                            lambda message: rates.append(message.data))
    ros.wait_until(lambda: len(rates) >= 2 and rates[-1] > 0, 120,
                   what="the view's frame rate, drawing")
    print('the view drew %s frames per second' % ', '.join('%.1f' % rate for rate in rates))

    # Pause (Alt+U), then Play (Alt+A) once the panel shows the world paused.
    window.press('alt+u')
    ros.wait_until(lambda: api.get_physics_properties().pause, 60, what='the world paused')

    # Alt+A is Play's only once the panel has seen the pause (it asks each second): pressed until
    # the world plays; pressed again after that it does nothing (the button says Pause).
    def played():
        window.press('alt+a')
        try:
            return ros.wait_until(lambda: not api.get_physics_properties().pause, 3,
                                  what='the world playing')
        except TimeoutError:
            return False
    ros.wait_until(played, 120, what='the world playing again')

    # Insert tab (Alt+I), its model list (Alt+D), "Cafe table" chosen by typing, Insert (Alt+N).
    window.press('alt+i', 'alt+d', 'C', 'a', 'f', 'e')
    for expected in ('cafe_table_0', 'cafe_table_1'):
        window.press('alt+n')
        ros.wait_until(lambda: expected in model_names(api), 60, what=expected)
    assert model_names(api) == ['cafe_table_0', 'cafe_table_1']
    # The panel says what it did (its reply may come after the model shows in the world).
    ros.wait_until(lambda: 'gazebo_ros_panels: inserted cafe_table_1' in window.log(),
                   60, what="the panel's report of the second insert")
    assert window.gzclient.poll() is None, window.log()


def test_a_click_in_the_view_inserts_the_chosen_model_there(ros, rospy_client):
    start_sim(ros, ENGINES[0])
    api = GazeboApi(rospy_client)
    window = GazeboWindow(ros)
    targets = (('cafe_table_0', (1.0, 0.5, 0.0)), ('cafe_table_1', (-1.0, 1.0, 0.0)))
    for expected, target in targets:
        # Insert tab, its list, "Cafe table" typed, Insert by clicking (Alt+C), then the click.
        window.insert_by_click('Cafe', 'Cafe table', target)
        ros.wait_until(lambda: expected in model_names(api), 60, what=expected)
        position = api.get_model_state(expected, '').pose.position
        assert math.hypot(position.x - target[0], position.y - target[1]) < 0.05, position
        assert abs(position.z) < 0.05, position
    assert window.gzclient.poll() is None, window.log()


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
