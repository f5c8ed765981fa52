"""rviz started as the book starts it, on a test's display, again after a crash as it starts."""
from gazebo_ros.world_view import ended_by_crash
from onedof_harness.private_ros import exit_status_text

# rviz starts in all, at most, where each start crashes.
RVIZ_CRASH_STARTS = 3


class BookRviz:
    """`rosrun rviz rviz [-d config]` as the book starts it, on `display`. rviz drawing in software
    (Mesa's llvmpipe) now and then crashes as it starts, inside LLVM compiling a shader (LLVM's
    issue 57850): as gzclient's view and the tutorial player do, a crashed rviz is started again,
    RVIZ_CRASH_STARTS times in all; an rviz that ends any other way fails the test."""

    def __init__(self, ros, config, display):
        self.ros, self.display = ros, display
        self.args = ['-d', str(config)] if config else []
        self.starts = 0
        self.proc = None
        self.procs = []  # every rviz started, the last one running
        self._start()

    def _start(self):
        self.starts += 1
        self.proc = self.ros.start(['rosrun', 'rviz', 'rviz'] + self.args,
                                   name='rviz_%d' % self.starts, may_exit=True,
                                   env={'DISPLAY': self.display, 'LIBGL_ALWAYS_SOFTWARE': '1'})
        self.procs.append(self.proc)

    def keep_up(self):
        status = self.proc.poll()
        if status is None:
            return
        if ended_by_crash(status) and self.starts < RVIZ_CRASH_STARTS:
            print('rviz crashed (%s) as it started; starting it again' % exit_status_text(status))
            self._start()
            return
        raise AssertionError('rviz (start %d of at most %d) exited (%s); its log ends:\n%s' % (
            self.starts, RVIZ_CRASH_STARTS, exit_status_text(status),
            self.ros.log_text(self.proc)[-1500:]))
