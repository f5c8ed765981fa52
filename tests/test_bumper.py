"""libgazebo_ros_bumper.so on `contact` sensors over real ROS, on every engine, on crates of our
own making: a 10 kg crate resting on the ground, laid on its side (turned a quarter about x),
reports at each update of its sensor (10 Hz of sim time) the contacts of the 100 steps since the
last, each between its collision and the ground's, named as Gazebo names them: normals up and
positions on its bottom face in the world frame, the wrench on the crate in its own link's frame
(m g along the link's y, which points up), totalling m g; a crate held in the air by no gravity
reports no contact; a sensor whose <collision> its link lacks is said so at spawn and reports
none."""
import math

import pytest

from api_client import pose
from onedof_harness.private_ros import wait_until
from test_imu_ft import listen

MASS = 10.0
G = 9.8
SIZE = (0.4, 0.3, 0.2)  # the crate's box


def crate_sdf(name, gravity=True, collision='collision'):
    ixx = MASS / 12 * (SIZE[1] ** 2 + SIZE[2] ** 2)
    iyy = MASS / 12 * (SIZE[0] ** 2 + SIZE[2] ** 2)
    izz = MASS / 12 * (SIZE[0] ** 2 + SIZE[1] ** 2)
    return """<sdf version="1.6"><model name="{name}"><link name="link">
  <gravity>{gravity}</gravity>
  <inertial><mass>{mass}</mass><inertia><ixx>{ixx}</ixx><iyy>{iyy}</iyy><izz>{izz}</izz>
    </inertia></inertial>
  <collision name="collision"><geometry><box><size>{sx} {sy} {sz}</size></box></geometry>
  </collision>
  <sensor type="contact" name="bumper">
    <update_rate>10</update_rate>
    <contact><collision>{collision}</collision><topic>{name}_contacts</topic></contact>
    <plugin name="bumper_plugin" filename="libgazebo_ros_bumper.so">
      <bumperTopicName>{name}_bumper</bumperTopicName>
      <frameName>world</frameName>
    </plugin>
  </sensor>
</link></model></sdf>""".format(name=name, gravity='true' if gravity else 'false', mass=MASS,
                                 ixx=ixx, iyy=iyy, izz=izz, sx=SIZE[0], sy=SIZE[1], sz=SIZE[2],
                                 collision=collision)


def quarter_about_x(z):
    p = pose(z=z)
    p.orientation.x, p.orientation.w = math.sin(math.pi / 4), math.cos(math.pi / 4)
    return p


def test_a_crate_on_the_ground_reports_its_weight_and_one_in_the_air_no_contact(
        shared_sim, ros, rospy_client, engine):
    from gazebo_msgs.msg import ContactsState
    api = shared_sim
    api.set_gravity(0, 0, -G)
    # On its side: the link's y axis points up and its 0.3 m side is its height.
    for name, xml, at in [('crate', crate_sdf('crate'), quarter_about_x(SIZE[1] / 2)),
                          ('balloon', crate_sdf('balloon', gravity=False), pose(3, 0, 2)),
                          ('misnamed', crate_sdf('misnamed', collision='nope'), pose(-3, 0, 0.1))]:
        spawned = api.spawn_sdf_model(name, xml, '', at, '')
        assert spawned.success, spawned.status_message
    assert api.step_simulation(1000).success  # the crate settles
    crate = listen(ros, rospy_client, '/crate_bumper', ContactsState)
    balloon = listen(ros, rospy_client, '/balloon_bumper', ContactsState)
    misnamed = listen(ros, rospy_client, '/misnamed_bumper', ContactsState)
    # A period at a time: each topic keeps one message in its queue, as upstream's.
    for period in (11, 12):
        assert api.step_simulation(100).success
        for heard in (crate, balloon, misnamed):
            wait_until(lambda: heard and heard[-1].header.stamp.to_nsec() >= period * 100000000,
                       30, what='the contacts at %d ms' % (period * 100))

    msg = crate[-1]
    assert msg.header.frame_id == 'world'
    assert [m.header.stamp.to_nsec() for m in crate] == [1100000000, 1200000000]
    # One state for each of the 100 steps since the last update, each of the one pair in touch.
    assert len(msg.states) == 100
    fz = []
    for i, state in enumerate(msg.states):
        assert state.collision1_name == 'crate::link::collision'
        assert state.collision2_name == 'ground_plane::link::collision'
        step_time = 1.101 + 0.001 * i
        assert state.info.startswith(
            'Debug:  i:(%d/100)     my geom:crate::link::collision   other geom:'
            'ground_plane::link::collision         time:' % i), state.info
        assert state.info.endswith('%.9f\n' % step_time), state.info
        count = len(state.wrenches)
        assert count >= 3
        assert len(state.contact_positions) == len(state.contact_normals) == len(state.depths) == count
        total = [0.0] * 6
        for wrench, position, normal, depth in zip(state.wrenches, state.contact_positions,
                                                    state.contact_normals, state.depths):
            assert (normal.x, normal.y, normal.z) == (pytest.approx(0, abs=1e-6),
                                                     pytest.approx(0, abs=1e-6),
                                                     pytest.approx(1, abs=1e-6))
            assert abs(position.z) <= 0.002 and 0 <= depth <= 0.002, (position, depth)
            assert abs(position.x) <= SIZE[0] / 2 + 1e-3 and abs(position.y) <= SIZE[2] / 2 + 1e-3
            for k, value in enumerate((wrench.force.x, wrench.force.y, wrench.force.z,
                                       wrench.torque.x, wrench.torque.y, wrench.torque.z)):
                total[k] += value
        t = state.total_wrench
        assert [t.force.x, t.force.y, t.force.z, t.torque.x, t.torque.y, t.torque.z] == [
            pytest.approx(v, abs=1e-9) for v in total]
        # In the crate's frame: the ground pushes along its y axis, which points up.
        assert abs(t.force.x) <= 0.05 * MASS * G and abs(t.force.z) <= 0.05 * MASS * G, t.force
        fz.append(t.force.y)
    assert sum(fz) / len(fz) == pytest.approx(MASS * G, rel=0.01), fz
    assert all(f == pytest.approx(MASS * G, rel=0.05) for f in fz), fz

    for heard in (balloon, misnamed):
        assert [m.header.stamp.to_nsec() for m in heard] == [1100000000, 1200000000]
        assert all(m.states == [] for m in heard)
    log = ros.log_text('sim_' + engine)
    assert log.count("libgazebo_ros_bumper.so of sensor 'bumper' (model 'misnamed'): "
                     "<contact><collision> 'nope' is no collision of link 'link'") == 1, log
