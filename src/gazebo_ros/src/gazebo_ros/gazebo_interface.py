"""gazebo_ros.gazebo_interface: the helpers that scripts written for Gazebo import, with Noetic's
signatures, calling onedof_sim's services (this workspace's simulator standing in for Gazebo).

Each returns the service's success flag and logs its status message, as Gazebo's do.
"""
import rospy

from gazebo_msgs.srv import SetModelConfiguration, SpawnModel
from onedof_sim.tools.spawn_cli import SpawnError
from onedof_sim.tools.spawn_model import call


def _succeeded(gazebo_namespace, service, srv_type, *request):
    rospy.loginfo('Calling service %s/%s of onedof_sim (standing in for Gazebo)',
                  gazebo_namespace.rstrip('/'), service)
    try:
        response = call(gazebo_namespace, service, srv_type, *request)
    except SpawnError as e:
        rospy.logerr(str(e))
        return False
    rospy.loginfo('%s status: %s', service, response.status_message)
    return response.success


def spawn_sdf_model_client(model_name, model_xml, robot_namespace, initial_pose, reference_frame,
                           gazebo_namespace):
    return _succeeded(gazebo_namespace, 'spawn_sdf_model', SpawnModel, model_name, model_xml,
                      robot_namespace, initial_pose, reference_frame)


def spawn_urdf_model_client(model_name, model_xml, robot_namespace, initial_pose, reference_frame,
                            gazebo_namespace):
    return _succeeded(gazebo_namespace, 'spawn_urdf_model', SpawnModel, model_name, model_xml,
                      robot_namespace, initial_pose, reference_frame)


def set_model_configuration_client(model_name, model_param_name, joint_names, joint_positions,
                                   gazebo_namespace):
    return _succeeded(gazebo_namespace, 'set_model_configuration', SetModelConfiguration,
                      model_name, model_param_name, joint_names, joint_positions)
