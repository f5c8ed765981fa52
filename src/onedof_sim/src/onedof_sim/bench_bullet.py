"""Steps per second of the pybullet engine: bare pybullet against the ROS node, side by side.

  python -m onedof_sim.bench_bullet [--seconds S]     (under the venv python, devel sourced)

bare_pybullet_steps_per_second() steps the very world the node would build (same models, same
settings) with pybullet's stepSimulation alone: the physics limit. node_steps_per_second() runs
`rosrun onedof_sim onedof_sim_bullet` as fast as possible (max_update_rate 0) on a private
roscore and reads its sim time. Both take the tutorial robot and the cafe table by default.
"""
import argparse
import os
import time

import rospkg

from onedof_sim.bullet_world import BulletWorld, ModelFormat, Pose, Vec3


def tutorial_models():
    """[(name, xml, ModelFormat, x)]: the tutorial robot at the origin, the cafe table at 0.85."""
    packages = rospkg.RosPack()
    robot = os.path.join(packages.get_path('minimal_robot_description'),
                         'minimal_robot_description.urdf')
    table = os.path.join(packages.get_path('onedof_sim'), 'models', 'cafe_table', 'model.sdf')
    models = []
    for name, path, model_format, x in (('one_DOF_robot', robot, ModelFormat.URDF, 0.0),
                                        ('cafe_table', table, ModelFormat.SDF, 0.85)):
        with open(path) as f:
            models.append((name, f.read(), model_format, x))
    return models


def bare_pybullet_steps_per_second(models, seconds=3.0):
    """Steps per wall second of pybullet's stepSimulation on the world of `models`
    ([(name, xml, ModelFormat, x)]), nothing else in the loop."""
    world = BulletWorld()
    try:
        for name, xml, model_format, x in models:
            status = world.spawn(name, xml, model_format, Pose(Vec3(x, 0.0, 0.0)))
            if not status.ok:
                raise ValueError(status.message)
        step = world.physics_client.stepSimulation
        steps = 0
        start = time.perf_counter()
        until = start + seconds
        while True:
            for _ in range(100):
                step()
            steps += 100
            now = time.perf_counter()
            if now >= until:
                return steps / (now - start)
    finally:
        world.close()


def node_steps_per_second(models, seconds=3.0):
    """Steps per wall second of the pybullet node running as fast as possible with `models`,
    from its sim time (get_world_properties) over a wall-clock window."""
    import rospy
    from onedof_sim.private_ros import PrivateRos
    from onedof_sim.srv import GetWorldProperties, SpawnModel
    from std_srvs.srv import Empty
    from geometry_msgs.msg import Pose as PoseMsg

    with PrivateRos() as ros:
        ros.start(['rosrun', 'onedof_sim', 'onedof_sim_bullet', '-u', '_max_update_rate:=0'],
                  name='sim_bullet')
        ros.wait_for_service('/gazebo/unpause_physics', 60)
        os.environ.update(ROS_MASTER_URI=ros.master_uri, ROS_HOSTNAME='127.0.0.1')
        rospy.init_node('bench_bullet', anonymous=True, disable_signals=True)
        try:
            spawn = rospy.ServiceProxy('/gazebo/spawn_urdf_model', SpawnModel)
            for name, xml, _, x in models:
                pose = PoseMsg()
                pose.position.x, pose.orientation.w = x, 1.0
                res = spawn(name, xml, '', pose, '')
                if not res.success:
                    raise ValueError(res.status_message)
            world = rospy.ServiceProxy('/gazebo/get_world_properties', GetWorldProperties,
                                       persistent=True)
            rospy.ServiceProxy('/gazebo/unpause_physics', Empty)()
            time.sleep(0.5)  # past the start-up transient
            wall0, sim0 = time.perf_counter(), world().sim_time
            time.sleep(seconds)
            wall1, sim1 = time.perf_counter(), world().sim_time
            step = 0.001  # the node's default step
            return (sim1 - sim0) / step / (wall1 - wall0)
        finally:
            rospy.signal_shutdown('benchmark done')


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--seconds', type=float, default=5.0, help='wall seconds per measurement')
    args = parser.parse_args()
    models = tutorial_models()
    bare = bare_pybullet_steps_per_second(models, args.seconds)
    node = node_steps_per_second(models, args.seconds)
    print('tutorial robot + cafe table, %g s each' % args.seconds)
    print('bare pybullet stepSimulation: %8.0f steps/s' % bare)
    print('onedof_sim_bullet node:       %8.0f steps/s  (%.2f of bare pybullet)'
          % (node, node / bare))


if __name__ == '__main__':
    main()
