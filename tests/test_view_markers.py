"""The world as Gazebo's window draws it, over real ROS on every engine: the simulator's view
markers (/gazebo/visual_markers, collision_markers, joint_markers, com_markers, inertia_markers,
contact_markers; src/onedof_sim/src/ros/view_markers.h). A URDF and an SDF with a named material,
an rgba colour, explicit SDF colours and meshes (package:// and model:// URIs) give markers of
those colours where their links put them, the meshes as file:// URIs rviz loads; a joint's axis
and a link's centre of mass and inertia box are where the model puts them; contacts appear where a
box rests on the ground; markers follow their links, a deleted model's are deleted, and a view is
published to whoever subscribes, paused or running. The window's own streams, the sim time
(/gazebo/view_clock) and the models' states (/gazebo/view_model_states), come at the views' rate,
not at every step, and end at the world's state where it stops."""
import math
import os

import pytest

from api_client import BOX_SDF as PLAIN_BOX_SDF, pose
from onedof_harness.private_ros import wait_until
# The module's simulators find the test model's meshes (shared_sim_env); api: the module's paused
# simulator of each engine, with no model.
from test_mesh_collisions import MODELS, api, shared_sim_env  # noqa: F401

MESHES = os.path.join(MODELS, 'onedof_mesh_block', 'meshes')
# Gazebo/Grey's and Gazebo/Blue's diffuse colours (Gazebo's gazebo.material).
GREY, BLUE = (0.7, 0.7, 0.7, 1.0), (0.0, 0.0, 1.0, 1.0)

# Link `base` (a red box above its origin and a green STL mesh beside it; the inertia of a uniform
# 2 kg box of 0.4 x 0.5 x 0.6 m about its centre), and link `arm` on a revolute joint about y at
# 0.5 m, a cylinder shown in Gazebo/Blue by its <gazebo> block. Spawned into the paused world, it
# stays where it is spawned.
URDF = """<?xml version="1.0"?>
<robot name="painted">
  <link name="base">
    <inertial><origin xyz="0 0 0.1"/><mass value="2"/>
      <inertia ixx="0.101667" ixy="0" ixz="0" iyy="0.086667" iyz="0" izz="0.068333"/></inertial>
    <visual><origin xyz="0 0 0.1"/><geometry><box size="0.2 0.3 0.4"/></geometry>
      <material name="red"><color rgba="1 0 0 1"/></material></visual>
    <visual><origin xyz="0.5 0 0"/>
      <geometry><mesh filename="package://onedof_mesh_block/meshes/unit_block.stl"
                      scale="0.3 0.3 0.1"/></geometry>
      <material name="green"><color rgba="0 1 0 1"/></material></visual>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.2 0.3 0.4"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>
    <visual><origin xyz="0 0 0.2"/><geometry><cylinder radius="0.05" length="0.4"/></geometry>
    </visual>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="arm"/><origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/>
  </joint>
  <gazebo reference="arm"><material>Gazebo/Blue</material></gazebo>
</robot>
"""

# A static model: Gazebo/Wood on one box, explicit colours on another, and a COLLADA mesh named by
# model:// with no material of its own (rviz shows the file's own materials).
SDF = """<?xml version="1.0"?>
<sdf version="1.6">
  <model name="wooden">
    <static>true</static>
    <link name="body">
      <visual name="wood"><pose>0 0 0.5 0 0 0</pose>
        <geometry><box><size>1 0.5 0.1</size></box></geometry>
        <material><script><uri>file://media/materials/scripts/gazebo.material</uri>
          <name>Gazebo/Wood</name></script></material></visual>
      <visual name="tinted"><pose>0 1 0.5 0 0 0</pose>
        <geometry><sphere><radius>0.1</radius></sphere></geometry>
        <material><ambient>0.1 0.2 0.3 1</ambient><diffuse>0.2 0.4 0.6 1</diffuse></material>
      </visual>
      <visual name="wedge">
        <geometry><mesh><uri>model://onedof_mesh_block/meshes/wedge.dae</uri></mesh></geometry>
      </visual>
    </link>
  </model>
</sdf>
"""

# api_client's free 0.2 m box of 1 kg, with a Gazebo/Red visual, dropped onto the ground.
BOX_SDF = PLAIN_BOX_SDF.replace('</link>', """<visual name="visual">
        <geometry><box><size>0.2 0.2 0.2</size></box></geometry>
        <material><script><name>Gazebo/Red</name></script></material></visual>
    </link>""")


def markers_of(rospy, topic, predicate, what, timeout=60):
    """The ADDed markers of the first message on /gazebo/<topic> whose ADDs satisfy predicate."""
    from visualization_msgs.msg import Marker, MarkerArray

    def added():
        msg = rospy.wait_for_message('/gazebo/' + topic, MarkerArray, timeout=30)
        markers = [m for m in msg.markers if m.action == Marker.ADD]
        return markers if predicate(markers) else None
    return wait_until(added, timeout, what=what)


def of_model(markers, model):
    return [m for m in markers if m.ns == model]


def color(marker):
    return (marker.color.r, marker.color.g, marker.color.b, marker.color.a)


def position(marker):
    return (marker.pose.position.x, marker.pose.position.y, marker.pose.position.z)


def scale(marker):
    return (marker.scale.x, marker.scale.y, marker.scale.z)


def test_urdf_visuals_have_their_colours_poses_and_mesh_files(api, rospy_client):
    from visualization_msgs.msg import Marker
    res = api.spawn_urdf_model('painted', URDF, '', pose(1, 2, 0), '')
    assert res.success, res.status_message
    markers = markers_of(rospy_client, 'visual_markers', lambda m: of_model(m, 'painted'),
                         'the painted robot among the visual markers')
    by_type = {m.type: m for m in of_model(markers, 'painted')}
    assert sorted(by_type) == sorted([Marker.CUBE, Marker.MESH_RESOURCE, Marker.CYLINDER])
    box, mesh, arm = by_type[Marker.CUBE], by_type[Marker.MESH_RESOURCE], by_type[Marker.CYLINDER]
    assert box.header.frame_id == 'world'
    assert color(box) == pytest.approx((1, 0, 0, 1))
    assert position(box) == pytest.approx((1, 2, 0.1))
    assert scale(box) == pytest.approx((0.2, 0.3, 0.4))
    assert mesh.mesh_resource == 'file://' + os.path.join(MESHES, 'unit_block.stl')
    assert color(mesh) == pytest.approx((0, 1, 0, 1))
    assert position(mesh) == pytest.approx((1.5, 2, 0))
    assert scale(mesh) == pytest.approx((0.3, 0.3, 0.1))
    assert not mesh.mesh_use_embedded_materials
    # The arm's <gazebo> material: Gazebo/Blue; its cylinder 0.2 m above the joint at 0.5 m.
    assert color(arm) == pytest.approx(BLUE)
    assert position(arm) == pytest.approx((1, 2, 0.7))
    assert scale(arm) == pytest.approx((0.1, 0.1, 0.4))
    # The world's ground: Gazebo's grey, its top just below z = 0.
    ground = of_model(markers, 'ground_plane')
    assert len(ground) == 1 and color(ground[0]) == pytest.approx(GREY)
    top = ground[0].pose.position.z + ground[0].scale.z / 2
    assert -0.01 < top <= 0


def test_sdf_visuals_have_named_and_given_colours_and_model_uri_meshes(api, rospy_client):
    from visualization_msgs.msg import Marker
    res = api.spawn_sdf_model('wooden', SDF, '', pose(-1, 0, 0), '')
    assert res.success, res.status_message
    markers = of_model(markers_of(rospy_client, 'visual_markers',
                                  lambda m: of_model(m, 'wooden'),
                                  'the wooden model among the visual markers'), 'wooden')
    by_type = {m.type: m for m in markers}
    assert sorted(by_type) == sorted([Marker.CUBE, Marker.SPHERE, Marker.MESH_RESOURCE])
    wood, tinted, wedge = by_type[Marker.CUBE], by_type[Marker.SPHERE], by_type[Marker.MESH_RESOURCE]
    # Gazebo/Wood's pass colour (its texture is not drawn), as the cameras draw it.
    assert color(wood) == pytest.approx((1, 1, 1, 1))
    assert position(wood) == pytest.approx((-1, 0, 0.5))
    assert color(tinted) == pytest.approx((0.2, 0.4, 0.6, 1))
    assert position(tinted) == pytest.approx((-1, 1, 0.5))
    assert scale(tinted) == pytest.approx((0.2, 0.2, 0.2))
    assert wedge.mesh_resource == 'file://' + os.path.join(MESHES, 'wedge.dae')
    assert wedge.mesh_use_embedded_materials and color(wedge) == (0, 0, 0, 0)


def test_joint_axis_centre_of_mass_and_inertia_box_are_where_the_model_puts_them(
        api, rospy_client):
    from visualization_msgs.msg import Marker
    res = api.spawn_urdf_model('painted', URDF, '', pose(1, 2, 0), '')
    assert res.success, res.status_message
    joints = of_model(markers_of(rospy_client, 'joint_markers', lambda m: of_model(m, 'painted'),
                                 'the robot among the joint markers'), 'painted')
    arrows = [m for m in joints if m.type == Marker.ARROW]
    assert len(arrows) == 1
    start, end = arrows[0].points
    assert (start.x, start.y, start.z) == pytest.approx((1, 2, 0.5))
    direction = (end.x - start.x, end.y - start.y, end.z - start.z)
    length = math.sqrt(sum(c * c for c in direction))
    assert [c / length for c in direction] == pytest.approx([0, 1, 0], abs=1e-9)

    coms = of_model(markers_of(rospy_client, 'com_markers', lambda m: of_model(m, 'painted'),
                               'the robot among the centre of mass markers'), 'painted')
    assert sorted(position(m) for m in coms) == pytest.approx(sorted([(1, 2, 0.1), (1, 2, 0.5)]))
    heavy = max(coms, key=lambda m: m.scale.x)
    # A sphere of lead of 2 kg: 2 * (3 * 2 / (4 pi 11340))^(1/3) m across.
    assert heavy.scale.x == pytest.approx(2 * (3 * 2 / (4 * math.pi * 11340)) ** (1 / 3))

    # The base's inertia is a uniform 2 kg box's of 0.4 x 0.5 x 0.6 m (Ixx = m (y^2 + z^2) / 12,
    # ...): its inertia box has those sides.
    boxes = of_model(markers_of(rospy_client, 'inertia_markers', lambda m: of_model(m, 'painted'),
                                'the robot among the inertia markers'), 'painted')
    base = next(m for m in boxes if position(m) == pytest.approx((1, 2, 0.1)))
    sides = sorted(scale(base))
    assert sides == pytest.approx([0.4, 0.5, 0.6], abs=0.005)


def test_markers_follow_their_links_and_contacts_appear_where_a_box_rests(api, rospy_client):
    from visualization_msgs.msg import Marker
    res = api.spawn_sdf_model('box', BOX_SDF, '', pose(0.5, -0.5, 1.0), '')
    assert res.success, res.status_message
    res = api.step_simulation(2000)  # it falls and comes to rest on the ground
    assert res.success, res.status_message

    def resting(markers):
        box = of_model(markers, 'box')
        return box and abs(box[0].pose.position.z - 0.1) < 0.005
    box = of_model(markers_of(rospy_client, 'visual_markers', resting,
                              'the box marker resting on the ground'), 'box')[0]
    assert color(box) == pytest.approx((1, 0, 0, 1))
    assert position(box)[:2] == pytest.approx((0.5, -0.5), abs=0.01)

    contacts = markers_of(rospy_client, 'contact_markers', lambda m: len(m) == 2,
                          'the resting box\'s contacts')
    points = next(m for m in contacts if m.type == Marker.SPHERE_LIST).points
    normals = next(m for m in contacts if m.type == Marker.LINE_LIST).points
    assert points and len(normals) == 2 * len(points)
    for p in points:  # under the box, on the ground
        assert abs(p.x - 0.5) <= 0.11 and abs(p.y + 0.5) <= 0.11 and abs(p.z) < 0.01
    for start, end in zip(normals[::2], normals[1::2]):  # vertical
        assert abs(end.z - start.z) == pytest.approx(0.1, abs=1e-3)


def test_a_deleted_models_markers_are_deleted_and_a_new_subscriber_gets_the_world(
        api, rospy_client):
    from visualization_msgs.msg import Marker, MarkerArray
    assert api.spawn_sdf_model('box', BOX_SDF, '', pose(z=0.1), '').success
    assert api.spawn_sdf_model('wooden', SDF, '', pose(-1, 0, 0), '').success
    markers_of(rospy_client, 'collision_markers', lambda m: of_model(m, 'box'),
               'the box among the collision markers')
    heard = []
    subscriber = rospy_client.Subscriber('/gazebo/visual_markers', MarkerArray, heard.append)
    try:
        wait_until(lambda: any(of_model(msg.markers, 'box') for msg in heard), 60,
                   what='the box among the visual markers')
        assert api.delete_model('box').success
        wait_until(lambda: any(m.ns == 'box' and m.action == Marker.DELETE
                               for msg in heard for m in msg.markers), 60,
                   what='the deleted box\'s marker deleted')
        last = heard[-1]
        assert not [m for m in last.markers if m.ns == 'box' and m.action == Marker.ADD]
        assert [m for m in last.markers if m.ns == 'wooden' and m.action == Marker.ADD]
    finally:
        subscriber.unregister()
    # Unsubscribed, the view is no one's; a new subscriber is sent the world as it is.
    markers = markers_of(rospy_client, 'visual_markers', lambda m: of_model(m, 'wooden'),
                         'the world to a new subscriber')
    assert not of_model(markers, 'box')


def test_the_windows_clock_and_model_states_come_at_the_views_rate(api, rospy_client):
    from gazebo_msgs.msg import ModelStates
    from rosgraph_msgs.msg import Clock
    assert api.spawn_sdf_model('box', BOX_SDF, '', pose(0.5, -0.5, 1.0), '').success
    clocks, states = [], []
    subscribers = [rospy_client.Subscriber('/gazebo/view_clock', Clock, clocks.append),
                   rospy_client.Subscriber('/gazebo/view_model_states', ModelStates,
                                           states.append)]
    try:
        wait_until(lambda: clocks and states, 60, what='the view clock and model states')
        start = api.get_world_properties().sim_time
        res = api.step_simulation(2000)  # 2 s of sim time: the box falls and comes to rest
        assert res.success, res.status_message
        end = api.get_world_properties().sim_time
        assert end == pytest.approx(start + 2.0, abs=1e-9)
        # The paused world's time and states reach the window after the run.
        wait_until(lambda: clocks[-1].clock.to_sec() == pytest.approx(end, abs=1e-9), 60,
                   what='the view clock at the end of the run')
        box = api.get_model_state('box', '').pose.position
        wait_until(lambda: dict(zip(states[-1].name, states[-1].pose))['box'].position.z ==
                   pytest.approx(box.z, abs=1e-9), 60, what='the box at rest in the states')
    finally:
        for subscriber in subscribers:
            subscriber.unregister()
    # During the run, a time at most every 0.1 s of sim time (kViewFrequency): some 20 for the
    # run's 2000 steps, not 2000; then the time where the run stopped.
    times = sorted({round(msg.clock.to_sec(), 9) for msg in clocks})
    running = [t for t in times if start < t < end - 1e-9]
    assert times[-1] == pytest.approx(end, abs=1e-9)
    gaps = [later - earlier for earlier, later in zip([start] + running, running)]
    assert all(gap >= 0.1 - 1e-9 for gap in gaps), gaps
    assert len(running) <= 20, running
