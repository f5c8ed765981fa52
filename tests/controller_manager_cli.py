"""`rosrun controller_manager controller_manager ...` in the book's namespace, for the tests."""

NS = '/one_DOF_robot'


def cli(ros, *args):
    out = ros.run(['rosrun', 'controller_manager', 'controller_manager'] + list(args)
                  + ['__ns:=' + NS])
    return out


def listing(ros):
    out = cli(ros, 'list')
    assert out.returncode == 0, out.stderr
    return out.stdout.splitlines()
