"""The simulator's view (gzclient: rviz on gazebo_ros/rviz/world.rviz) draws the world's visuals
in their materials' colours where the models stand, over real ROS on a private Xvfb: a Gazebo/Green
box shows green pixels where the view's camera projects it and nowhere else in the 3D panel. An
rviz that crashes (as Mesa's software renderer now and then makes it) is started again by the view
and draws the same; an rviz that is closed ends the view. Gazebo's view modes toggle while the
view runs: View > Wireframe and View > Transparent in the menu bar change every model's pixels,
and a model's right-click View > Wireframe or Transparent changes that model's alone."""
import math
import signal

import yaml

from api_client import GazeboApi, pose
from conftest import ENGINES, start_sim
from onedof_sim.tutorial.gazebo_window import (ARROW_GRAB, GazeboWindow, HandlesSeen,
                                               orbit_pixel)
from onedof_sim.tutorial.rviz_view import start_xvfb
from test_camera import box_sdf
from test_rviz_sensors import WORLD_RVIZ, region_around, screenshot_with, subscribers
from test_tutorial import count_pixels
from test_tutorial_rviz_failure import rviz_processes

HALF = 0.25  # the box's half side (box_sdf's 0.5 m)
# Gazebo/Green lit by rviz's light: green, the other channels dark (the grey ground and the
# dark background are neither).
green = lambda r, g, b: (g > 90) & (r < 50) & (b < 50)


def start_view(ros, display, may_exit=False):
    view = ros.start(['rosrun', 'gazebo_ros', 'gzclient'], name='gzclient',
                     env={'DISPLAY': display, 'LIBGL_ALWAYS_SOFTWARE': '1'}, may_exit=may_exit)
    ros.wait_until(lambda: subscribers(ros, '/gazebo/visual_markers', '/gzclient_'), 120,
                   what='the view to subscribe to the visual markers')
    return view


def spawn_green_box(rospy_client):
    api = GazeboApi(rospy_client)
    spawned = api.spawn_sdf_model('green_box', box_sdf('green_box', 2 * HALF, 'Gazebo/Green'), '',
                                  pose(1, 0.5, HALF), '')
    assert spawned.success, spawned.status_message


def assert_green_box_shown(ros, display, png):
    with open(WORLD_RVIZ) as f:
        config = f.read()
    corners = [(1 + dx, 0.5 + dy, HALF + dz) for dx in (-HALF, HALF) for dy in (-HALF, HALF)
               for dz in (-HALF, HALF)]
    panel = screenshot_with(
        ros, display, png,
        lambda png, panel: count_pixels(png, region_around(config, panel, corners), green) > 500,
        'the green box in the view')
    assert count_pixels(png, panel, green) == count_pixels(
        png, region_around(config, panel, corners), green), 'green off the box'


def test_the_view_draws_a_green_box_in_green_where_it_stands(ros, rospy_client, tmp_path):
    start_sim(ros, ENGINES[0])
    xvfb, display = start_xvfb(ros)
    view = start_view(ros, display)
    spawn_green_box(rospy_client)
    assert_green_box_shown(ros, display, tmp_path / 'view.png')
    ros.terminate(view)  # rviz before its X server
    ros.terminate(xvfb)


def test_a_crashed_rviz_is_started_again_and_a_closed_one_ends_the_view(ros, rospy_client,
                                                                        tmp_path):
    start_sim(ros, ENGINES[0])
    xvfb, display = start_xvfb(ros)
    view = start_view(ros, display, may_exit=True)
    spawn_green_box(rospy_client)
    crashed = ros.wait_until(lambda: rviz_processes(view), 60, what="the view's rviz")[0]
    crashed.send_signal(signal.SIGSEGV)
    said = 'gzclient: rviz crashed (status -11, SIGSEGV); starting it again on the same ' \
           'configuration (restart 1 of at most 3)'
    ros.wait_until(lambda: said in ros.log_text(view), 120, what='the view to say: ' + said)
    restarted = ros.wait_until(
        lambda: [proc for proc in rviz_processes(view) if proc.pid != crashed.pid], 120,
        what='a new rviz')[0]
    assert_green_box_shown(ros, display, tmp_path / 'view.png')
    assert view.poll() is None
    # Closed, not crashed: the view ends with it.
    restarted.send_signal(signal.SIGTERM)
    ros.wait_until(lambda: view.poll() is not None, 120, what='the view to end with its rviz')
    assert 'restart 2' not in ros.log_text(view)
    ros.terminate(xvfb)


# Two green boxes apart in the view: what the view modes change is measured on each.
MODE_BOXES = {'near': (1.0, 0.5), 'far': (0.5, -1.5)}
# The model handles' right-click menu: View is its 4th entry; Transparent and Wireframe in it.
VIEW_ENTRY = 4
VIEW_SUB_ENTRY = {'Transparent': 1, 'Wireframe': 2}


def greenness(png, region):
    """How green region (x0, y0, x1, y1) is: the sum over its pixels of green above the larger
    of red and blue (0 on the grey ground, its grid and the background)."""
    import matplotlib.image
    import numpy
    rgb = (matplotlib.image.imread(str(png))[..., :3] * 255).round()
    x0, y0, x1, y1 = region
    r, g, b = (rgb[y0:y1, x0:x1, i] for i in range(3))
    return float(numpy.clip(g - numpy.maximum(r, b), 0, None).sum())


def box_region(window, x, y, margin=3):
    """The screen region around where the window's view draws the box at (x, y)."""
    pixels = [orbit_pixel(window.view, window.panel, (x + dx, y + dy, HALF + dz))
              for dx in (-HALF, HALF) for dy in (-HALF, HALF) for dz in (-HALF, HALF)]
    xs, ys = [px for px, _ in pixels], [py for _, py in pixels]
    return (math.floor(min(xs)) - margin, math.floor(min(ys)) - margin,
            math.ceil(max(xs)) + margin + 1, math.ceil(max(ys)) + margin + 1)


def test_the_view_modes_make_the_world_or_one_model_wireframe_or_transparent(
        ros, rospy_client, tmp_path):
    start_sim(ros, ENGINES[0])
    api = GazeboApi(rospy_client)
    api.pause_physics()
    for name, (x, y) in MODE_BOXES.items():
        spawned = api.spawn_sdf_model(name, box_sdf(name, 2 * HALF, 'Gazebo/Green'), '',
                                      pose(x, y, HALF), '')
        assert spawned.success, spawned.status_message
    window = GazeboWindow(ros)
    regions = {name: box_region(window, x, y) for name, (x, y) in MODE_BOXES.items()}
    shots = iter(range(1000))

    def greens():
        """Each box's greenness in a steady screenshot of the window."""
        png = str(tmp_path / ('view_%d.png' % next(shots)))
        window.screenshot(png)
        return {name: greenness(png, region) for name, region in regions.items()}

    def greens_when(condition, what):
        return ros.wait_until(lambda: (lambda seen: seen if condition(seen) else None)(greens()),
                              120, interval=0.5, what=what)

    # Solid: each box a full square of green (its near faces, lit).
    solid = greens_when(lambda seen: all(green > 1e5 for green in seen.values()),
                        'both boxes drawn')
    ratio = lambda seen, name: seen[name] / solid[name]
    figures = {'solid': solid}
    # The display has a checkbox per model, as rviz's Marker display has one per namespace.
    saved = str(tmp_path / 'saved.rviz')
    window.read_view(saved)
    with open(saved) as f:
        displays = yaml.safe_load(f)['Visualization Manager']['Displays']
    visuals = next(display for display in displays if display['Name'] == 'Visuals')
    assert visuals['Class'] == 'gazebo_ros_panels/ModelVisuals'
    assert visuals['Models'] == {'ground_plane': True, 'near': True, 'far': True}, visuals

    def view_menu(key, said):
        before = window.log().count(said)
        window.press('alt+v', key)
        ros.wait_until(lambda: window.log().count(said) > before, 60, what='the panel: ' + said)

    # View > Wireframe: every model's triangles' edges only; off again, solid as before.
    view_menu('w', 'View: Wireframe on')
    wire = greens_when(lambda seen: all(ratio(seen, name) < 0.5 for name in seen),
                       'both boxes in wireframe')
    figures['world wireframe'] = wire
    assert all(ratio(wire, name) > 0.02 for name in wire), wire  # their edges drawn
    view_menu('w', 'View: Wireframe off')
    greens_when(lambda seen: all(abs(ratio(seen, name) - 1) < 0.02 for name in seen),
                'both boxes solid again')

    # View > Transparent: every model at half its alpha over the background.
    view_menu('t', 'View: Transparent on')
    clear = greens_when(lambda seen: all(ratio(seen, name) < 0.75 for name in seen),
                        'both boxes transparent')
    figures['world transparent'] = clear
    assert all(ratio(clear, name) > 0.3 for name in clear), clear
    view_menu('t', 'View: Transparent off')
    greens_when(lambda seen: all(abs(ratio(seen, name) - 1) < 0.02 for name in seen),
                'both boxes opaque again')

    # A model's right-click View: that model alone, checked in its menu.
    seen_handles = HandlesSeen(rospy_client)

    def model_view(name, mode):
        x, y = MODE_BOXES[name]
        window.show_handles()
        window.select(name, (x, y, 2 * HALF))  # a click on its top
        ros.wait_until(lambda: seen_handles.has_controls(name), 60, what=name + "'s handle")
        # The handles drawn before the mouse goes.
        window.screenshot(str(tmp_path / ('handles_%d.png' % next(shots))))
        window.choose_from_menu((x + ARROW_GRAB, y, HALF), VIEW_ENTRY, VIEW_SUB_ENTRY[mode])
        ros.wait_until(lambda: '[x] ' + mode in [
            entry.title for entry in seen_handles.markers[name].menu_entries], 60,
            what='%s checked in the menu of %s' % (mode, name))
        window.hide_handles()  # the handles' arrows are green too

    model_view('near', 'Wireframe')
    one_wire = greens_when(lambda seen: ratio(seen, 'near') < 0.5, 'the near box in wireframe')
    figures['near wireframe'] = one_wire
    assert abs(ratio(one_wire, 'far') - 1) < 0.02, one_wire
    model_view('far', 'Transparent')
    one_clear = greens_when(lambda seen: ratio(seen, 'far') < 0.75, 'the far box transparent')
    figures['far transparent'] = one_clear
    assert ratio(one_clear, 'far') > 0.3 and ratio(one_clear, 'near') < 0.5, one_clear
    for state, seen in figures.items():
        print('%s: %s' % (state, ', '.join('%s box %.0f (%.3f of solid)' % (
            name, seen[name], ratio(seen, name)) for name in MODE_BOXES)))
    assert window.gzclient.poll() is None, window.log()
    window.stop()
