"""The tutorial through the simulator's window: `play_tutorial --gui-table` opens gzclient on the
player's Xvfb, inserts the cafe table through the Gazebo panel's Insert tab by a click on the
ground, drags it to x = 0.85 by its x arrow with the mouse (xdotool), writes a screenshot of each
step, and plays the table phase; the link settles against the table within 0.01 rad of the
command line's run with the table where the drag left it, and every phase before the table is
that run's to a micro-radian (both lock-stepped)."""
import json

from onedof_sim.tutorial.gazebo_window import STEADY_PIXELS, WINDOW_SHOTS
from onedof_sim.tutorial.phases import TABLE_X
from onedof_sim.tutorial.rviz_view import differing_pixels, is_blank

from test_tutorial import SAME, play_tutorial

# Lock-step's figures, the summary alone: no plots, no in-sim run.
SUMMARY_ONLY = ('--no-figures', '--in-sim-phase-duration', '0')


def summary(output):
    with open(output / 'summary.json') as f:
        return json.load(f)


def test_the_table_placed_with_the_mouse_is_the_command_lines(tmp_path):
    gui = play_tutorial(tmp_path / 'gui', '--gui-table', *SUMMARY_ONLY)
    assert gui['returncode'] == 0, gui['stdout'][-4000:] + gui['stderr'][-4000:]
    by_mouse = summary(tmp_path / 'gui')
    x, y, z = by_mouse['table']
    print('the mouse left the table at (%.4f, %.4f, %.4f)' % (x, y, z))
    # Where the drag left it: the pixel the mouse stops on decides within a centimetre or so; the
    # click put it on the ground.
    assert abs(x - TABLE_X) < 0.02 and abs(y) < 0.05 and abs(z) < 0.01, (x, y, z)
    # A screenshot of each step, each one a picture changed from the one before.
    shots = [tmp_path / 'gui' / name for name in WINDOW_SHOTS]
    for shot in shots:
        assert shot.exists() and not is_blank(str(shot)), shot
    for before, after in zip(shots, shots[1:]):
        assert differing_pixels(str(before), str(after)) > STEADY_PIXELS, (before, after)
    assert not (tmp_path / 'gui' / 'rviz_final.png').exists()

    typed = play_tutorial(tmp_path / 'typed', '--table-x', repr(x), '--table-y', repr(y),
                          '--table-z', repr(z), '--no-screenshot', *SUMMARY_ONLY)
    assert typed['returncode'] == 0, typed['stdout'][-4000:] + typed['stderr'][-4000:]
    by_command = summary(tmp_path / 'typed')
    assert by_command['table'] == [x, y, z]
    for mouse_row, command_row in zip(by_mouse['phases'], by_command['phases']):
        tolerance = 0.01 if mouse_row['name'] == 'table_2.5' else SAME
        print('%s: settled at %.6f rad with the table placed by the mouse, %.6f by the command '
              'line' % (mouse_row['name'], mouse_row['settled'], command_row['settled']))
        assert abs(mouse_row['settled'] - command_row['settled']) < tolerance, \
            (mouse_row, command_row)
    assert [row['name'] for row in by_mouse['phases']][-1] == 'table_2.5'
