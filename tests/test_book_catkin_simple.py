"""The book's action packages as printed build with this workspace's catkin_simple: a package of
our own making in their shape (tests/book_action_server: catkin_simple's macros only, an action,
a message and a service generated from its folders, a library, an action server and client in
C++; it names actionlib but not actionlib_msgs, as example_action_server does) builds in an
overlay over this workspace, and its client gets its result from its server over real ROS."""
import os
import subprocess
import xml.etree.ElementTree as ElementTree

import pytest

from conftest import OVERLAY_TESTS_TIMEOUT, session_folder
from onedof_harness import book_client
from onedof_harness.private_ros import COMMAND_TIMEOUT
from onedof_sim.tools import workspace_root
from test_book_perception import answer, in_overlay

pytestmark = OVERLAY_TESTS_TIMEOUT

PACKAGE = 'book_action_server'


@pytest.fixture
def overlay_setup(tmp_path_factory):
    """The overlay's setup.bash, built once for the session's workers."""
    return book_client.shared_overlay(session_folder(tmp_path_factory, PACKAGE), (PACKAGE,))


def test_the_package_is_shaped_as_the_books_action_packages():
    """What makes the book's action packages fail under catkin_simple on Debian: actionlib among
    the build dependencies, actionlib_msgs not."""
    root = ElementTree.parse(os.path.join(workspace_root(), 'tests', PACKAGE, 'package.xml'))
    build_depends = [e.text for e in root.iter('build_depend')]
    assert 'actionlib' in build_depends and 'actionlib_msgs' not in build_depends
    assert 'catkin_simple' in [e.text for e in root.iter('buildtool_depend')]


def test_the_overlay_builds_with_this_workspaces_catkin_simple(overlay_setup):
    found = subprocess.run(in_overlay(overlay_setup, 'rospack find catkin_simple'),
                           capture_output=True, text=True, timeout=COMMAND_TIMEOUT)
    assert found.returncode == 0, found.stderr
    assert found.stdout.strip() == os.path.join(workspace_root(), 'src', 'catkin_simple')


def test_the_action_client_gets_its_result_from_the_server(ros, overlay_setup):
    server = ros.start(in_overlay(overlay_setup, 'rosrun %s countdown_server' % PACKAGE),
                       name='countdown_server')
    printed = answer(ros, overlay_setup, 'rosrun %s countdown_client 5 7' % PACKAGE)
    # Five steps down from 5, each with its feedback; the library's steps, the generated
    # message inside the generated action's result, and the generated service.
    assert printed['state'] == ['SUCCEEDED']
    assert printed['steps'] == ['5']
    assert printed['tally'] == ['1', '5']
    assert printed['squared'] == ['49']
    assert server.poll() is None, ros.log_text(server)
