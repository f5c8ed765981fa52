"""The summary of a run: each phase's figures from its recorded samples (settled angle, overshoot,
settling time, holding torque) beside their predictions, and the table of them in summary.md."""
from onedof_sim.tutorial import physics


def phase_summary(phase, recorder, start, end, expected_samples=None,
                  predict=physics.pd_prediction):
    """The phase's row of the summary from the recorder's samples in [start, end): settled angle,
    overshoot, settling time, holding torque against `predict`'s closed form. With
    expected_samples, a different count of position samples is an error (a lost sample)."""
    positions = recorder.between('jnt_pos', start, end)
    torques = recorder.between('jnt_trq', start, end)
    if len(positions) < 2 or len(torques) < 2:
        raise RuntimeError('phase %s recorded %d positions and %d torques: is the controller '
                           'running?' % (phase.name, len(positions), len(torques)))
    if expected_samples is not None and len(positions) != expected_samples:
        raise RuntimeError('phase %s recorded %d samples, not one per sampling period (%d)'
                           % (phase.name, len(positions), expected_samples))
    metrics = physics.step_metrics([t for t, _ in positions], [q for _, q in positions],
                                   start_value=positions[0][1])
    metrics['holding_torque'] = physics.tail_mean([t for t, _ in torques],
                                                  [u for _, u in torques])
    predicted, metrics['predicted_torque'] = predict(phase, metrics['settled'])
    metrics['met_table'] = ('tip rim at x = %.3f m, z = %.3f m' % physics.tip_rim(
        metrics['settled'])) if phase.table else ''
    metrics.update(name=phase.name, command=phase.command, predicted=predicted,
                   samples=len(positions))
    return metrics


SUMMARY_COLUMNS = (
    ('phase', 'name', '%s'), ('command (rad)', 'command', '%.2f'),
    ('settled (rad)', 'settled', '%.4f'), ('predicted (rad)', 'predicted', '%.4f'),
    ('overshoot (rad)', 'overshoot', '%.4f'), ('settling time (s)', 'settling_time', '%.2f'),
    ('holding torque (N m)', 'holding_torque', '%.3f'),
    ('predicted torque (N m)', 'predicted_torque', '%.3f'), ('met the table', 'met_table', '%s'))


def summary_table(rows):
    lines = ['| ' + ' | '.join(title for title, _, _ in SUMMARY_COLUMNS) + ' |',
             '|' + '---|' * len(SUMMARY_COLUMNS)]
    for row in rows:
        lines.append('| ' + ' | '.join(fmt % row[key] for _, key, fmt in SUMMARY_COLUMNS) + ' |')
    return lines


def summary_markdown(rows, physics_engine, free_run=False, in_sim_rows=()):
    lines = ['# Tutorial summary (%s engine, %s)'
             % (physics_engine, 'free-running' if free_run else 'lock-step'), '',
             'Predicted: where Kp (c - q) + m g d sin q = 0; with the table, the angle at which '
             'the link first touches the table top. Settling: within 0.02 rad of the settled '
             'angle. Times are sim time.', ''] + summary_table(rows)
    if in_sim_rows:
        lines += ['', '## The same phases through the in-simulator PID', '',
                  'effort_controllers/JointPositionController with the book\'s gains '
                  '(one_dof_ctl_params.yaml), run inside the simulator\'s step and sampled from '
                  'its state topic. Predicted: the command itself (the integral term removes '
                  'the droop) holding m g d sin c; on the table, p times the remaining error '
                  'plus the integral at its clamp.', ''] + summary_table(in_sim_rows)
    return '\n'.join(lines) + '\n'
