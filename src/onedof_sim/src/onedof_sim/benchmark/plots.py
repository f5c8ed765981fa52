"""The benchmark's plots, one per item that has one (matplotlib, headless): scaling (item 2),
service round trips (3), controller periods (4), pacing (5)."""
from onedof_sim.benchmark import report as bm


def _pyplot():
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot
    return pyplot


def _save(pyplot, figure, path):
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    pyplot.close(figure)


def write_scaling_plot(rates, labels, exponents, path):
    pyplot = _pyplot()
    figure, axes = pyplot.subplots(figsize=(7, 4.5))
    for key, by_links in rates.items():
        links = sorted(by_links)
        label = labels[key]
        if key in exponents:
            label += ' (cost per step ~ links^%.2f)' % exponents[key]
        axes.loglog(links, [by_links[n] for n in links], 'o-', label=label)
    axes.set_xlabel('moving links in the chain (revolute joints)')
    axes.set_ylabel('steps per second')
    axes.set_title('Scaling: URDF chains, as fast as possible, no ROS')
    axes.grid(True, which='both', alpha=0.3)
    axes.legend()
    _save(pyplot, figure, path)


def write_latency_plot(samples, name, path):
    pyplot = _pyplot()
    keys = list(samples)
    figure, axes = pyplot.subplots(figsize=(9, 4.5))
    for offset, target, color in ((-0.2, 'sim', 'tab:blue'), (0.2, 'bare', 'tab:gray')):
        p50 = [bm.percentile(samples[k][target], 50) for k in keys]
        p99 = [bm.percentile(samples[k][target], 99) for k in keys]
        positions = [i + offset for i in range(len(keys))]
        axes.bar(positions, p50, width=0.4, color=color,
                 label='%s p50 (line: p99)' % (name if target == 'sim'
                                               else 'bare roscpp service'))
        axes.vlines(positions, p50, p99, color='black')
    axes.set_xticks(range(len(keys)))
    axes.set_xticklabels(['%s\n%s\n%s' % (s.replace('_joint_', ' '), c, m) for c, m, s in keys],
                         fontsize=7)
    axes.set_yscale('log')
    axes.set_ylabel('round trip (us)')
    axes.set_title('Service round trips, %s against the bare service' % name)
    axes.legend()
    _save(pyplot, figure, path)


def write_pacing_plot(windows, name, path):
    pyplot = _pyplot()
    figure, axes = pyplot.subplots(figsize=(7, 3.5))
    axes.plot(range(1, len(windows) + 1), windows, 'o-', markersize=3)
    axes.axhline(1.0, color='gray', linewidth=0.8)
    for bound in (0.99, 1.01):
        axes.axhline(bound, color='gray', linestyle='--', linewidth=0.8)
    axes.set_xlabel('one-second window (wall time)')
    axes.set_ylabel('real-time factor')
    axes.set_title('Pacing at real-time factor 1, %s (dashed: +-1 %%)' % name)
    _save(pyplot, figure, path)


def write_period_plot(runs, path):
    pyplot = _pyplot()
    figure, axes = pyplot.subplots(figsize=(7, 4))
    for rate in sorted(runs):
        intervals = [interval * rate for interval in runs[rate]['wall_intervals']]
        axes.hist(intervals, bins=60, histtype='step', label='%d Hz' % rate, log=True)
    axes.set_xlabel('wall interval between jnt_pos arrivals / period')
    axes.set_ylabel('count')
    axes.set_title('Controller periods in wall time (1 = on time, 2 = one period missed)')
    axes.legend()
    _save(pyplot, figure, path)
