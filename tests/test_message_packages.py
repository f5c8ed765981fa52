"""control_msgs and controller_manager_msgs: the types ros_control's tools and clients exchange,
with Noetic's MD5 sums (a sum that differs makes rospy and roscpp refuse the connection)."""

import pytest

# Noetic's sums, taken from code generated from the released packages (gencpp, gennodejs and
# genlisp output published with projects that use them), not from this workspace's build.
NOETIC_CONTROLLER_MANAGER_MSGS_MD5 = {
    'ControllerState': 'aeb6b261d97793ab74099a3740245272',
    'ControllerStatistics': '697780c372c8d8597a1436d0e2ad3ba8',
    'ControllersStatistics': 'a154c347736773e3700d1719105df29d',
    'HardwareInterfaceResources': 'f25b55cbf1d1f76e82e5ec9e83f76258',
}
NOETIC_CONTROLLER_MANAGER_SRVS_MD5 = {
    'ListControllerTypes': 'c1d4cd11aefa9f97ba4aeb5b33987f4e',
    'ListControllers': '1341feb2e63fa791f855565d0da950d8',
    'LoadController': '647e5c54b8d6468952d8d31f1efe96c0',
    'ReloadControllerLibraries': '40e8c411fd1797d2e2c486018f846040',
    'SwitchController': 'b29a7abc673b2c54c14b54e50f8d06a5',
    'UnloadController': '647e5c54b8d6468952d8d31f1efe96c0',
}
NOETIC_CONTROL_MSGS_MD5 = {
    'GripperCommand': '680acaff79486f017132a7f198d40f08',
    'JointControllerState': '987ad85e4756f3aef7f1e5e7fe0595d1',
    'JointJog': '1685da700c8c2e1254afc92a5fb89c96',
    'JointTolerance': 'f544fe9c16cf04547e135dd6063ff5be',
    'JointTrajectoryControllerState': '10817c60c2486ef6b33e97dcd87f4474',
    'PidState': 'b138ec00e886c10e73f27e8712252ea6',
    # The action types' goal, result and feedback messages, and two of the wrappers actionlib
    # builds around them.
    'FollowJointTrajectoryGoal': '69636787b6ecbde4d61d711979bc7ecb',
    'FollowJointTrajectoryResult': '493383b18409bfb604b4e26c676401d2',
    'FollowJointTrajectoryFeedback': '10817c60c2486ef6b33e97dcd87f4474',
    'FollowJointTrajectoryActionGoal': 'cff5c1d533bf2f82dd0138d57f4304bb',
    'FollowJointTrajectoryActionFeedback': 'd8920dc4eae9fc107e00999cce4be641',
    'GripperCommandGoal': '86fd82f4ddc48a4cb6856cfa69217e43',
    'GripperCommandResult': 'e4cbff56d3562bcf113da5a5adeef91f',
    'GripperCommandFeedback': 'e4cbff56d3562bcf113da5a5adeef91f',
    'JointTrajectoryGoal': '2a0eff76c870e8595636c2a562ca298e',
    'PointHeadGoal': '8b92b1cd5e06c8a94c917dc3209a4c1d',
    'PointHeadFeedback': 'cce80d27fd763682da8805a73316cab4',
    'SingleJointPositionGoal': 'fbaaa562a23a013fd5053e5f72cbb35c',
    'SingleJointPositionFeedback': '8cee65610a3d08e0a1bded82f146f1fd',
    'SingleJointPositionActionGoal': '4b0d3d091471663e17749c1d0db90f61',
    'SingleJointPositionActionFeedback': '3503b7cf8972f90d245850a5d8796cfa',
}
NOETIC_CONTROL_SRVS_MD5 = {
    'QueryCalibrationState': '28af3beedcb84986b8e470dc5470507d',
    'QueryTrajectoryState': 'ec93cdecbd8062d761aa52b7c90cd44b',
}


def _wrong_sums(mode, package, expected):
    import rosmsg
    return ['%s/%s: %s, Noetic %s' % (package, name, got, md5)
            for name, md5 in sorted(expected.items())
            for got in [rosmsg.rosmsg_md5(mode, package + '/' + name)] if got != md5]


@pytest.mark.parametrize('kind, package, expected', [
    ('msg', 'controller_manager_msgs', NOETIC_CONTROLLER_MANAGER_MSGS_MD5),
    ('srv', 'controller_manager_msgs', NOETIC_CONTROLLER_MANAGER_SRVS_MD5),
    ('msg', 'control_msgs', NOETIC_CONTROL_MSGS_MD5),
    ('srv', 'control_msgs', NOETIC_CONTROL_SRVS_MD5),
])
def test_md5_sums_match_noetic(kind, package, expected):
    # What `rosmsg md5` / `rossrv md5` print, computed in this process (a CLI run per type costs
    # a Python start-up each).
    import rosmsg
    mode = rosmsg.MODE_MSG if kind == 'msg' else rosmsg.MODE_SRV
    wrong = _wrong_sums(mode, package, expected)
    assert not wrong, '\n'.join(wrong)


def test_generated_python_classes_carry_the_noetic_sums():
    # What rospy puts in a connection header: the generated class's sum, not rosmsg's.
    from control_msgs.msg import JointControllerState
    from controller_manager_msgs.srv import ListControllers, SwitchController
    assert JointControllerState._md5sum == NOETIC_CONTROL_MSGS_MD5['JointControllerState']
    assert ListControllers._md5sum == NOETIC_CONTROLLER_MANAGER_SRVS_MD5['ListControllers']
    assert SwitchController._md5sum == NOETIC_CONTROLLER_MANAGER_SRVS_MD5['SwitchController']
    assert SwitchController._request_class.BEST_EFFORT == 1
    assert SwitchController._request_class.STRICT == 2


def test_rossrv_cli_prints_the_noetic_sum(ros):
    out = ros.run(['rossrv', 'md5', 'controller_manager_msgs/LoadController'])
    assert out.stdout.strip() == NOETIC_CONTROLLER_MANAGER_SRVS_MD5['LoadController'], out.stderr
