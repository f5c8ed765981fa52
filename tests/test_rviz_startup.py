"""rviz starts without rospack's `Error: no such package media_export`: rviz asks rospack which
packages export Ogre media through media_export, which Debian does not package; this workspace's
src/media_export stands in for it."""
import subprocess

from book_rviz import BookRviz
from onedof_harness.private_ros import COMMAND_TIMEOUT
from onedof_sim.tutorial.rviz_view import start_xvfb


def publishers(ros, topic, prefix):
    _, _, (published, _, _) = ros.master().getSystemState('/test')
    return [node for name, nodes in published if name == topic for node in nodes
            if node.startswith(prefix)]


def test_rospack_finds_media_exports():
    result = subprocess.run(['rospack', 'plugins', '--attrib=ogre_media_path', 'media_export'],
                            capture_output=True, text=True, timeout=COMMAND_TIMEOUT)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ''


def test_rviz_starts_without_a_missing_media_export(ros):
    _, display = start_xvfb(ros)
    rviz = BookRviz(ros, None, display)

    def advertised():
        rviz.keep_up()
        return publishers(ros, '/clicked_point', '/rviz')
    # Its tools advertise their topics once its render system is up, which reads the packages'
    # media exports first.
    ros.wait_until(advertised, 300, what='rviz to advertise /clicked_point')
    for proc in rviz.procs:
        log = ros.log_text(proc)
        assert 'media_export' not in log, log
