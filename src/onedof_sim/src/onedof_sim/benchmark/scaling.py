"""Item 2, scaling: steps per second of each engine's bare loop on URDF chains of more and more
moving links (no ROS), and the exponent k of cost per step ~ links^k."""
import os

from onedof_sim.benchmark import report as bm
from onedof_sim.benchmark.graph import BareLoop, NotMeasured, engine_loop_command, say
from onedof_sim.benchmark.plots import write_scaling_plot

# The engine with a second solver, which ~quick_step picks (ODE's dWorldQuickStep): measured with
# both.
QUICK_STEP_ENGINE = 'ode'


def variants(engines):
    """(key, label, bare loop command) of each bare loop measured."""
    found = []
    for engine in engines:
        commands = [(engine, engine_loop_command(engine))]
        if engine == QUICK_STEP_ENGINE:
            commands.append((engine + '_quick', engine_loop_command(engine, quick_step=True)))
        found += [(key, 'bare loop, ' + ' '.join(command[2:]), command)
                  for key, command in commands]
    return found


def measure(bench):
    sizes = bench.sizes
    loop_variants = variants(bench.engines)
    labels = {key: label for key, label, _ in loop_variants}
    rates = {key: {} for key in labels}
    for links in sizes.chain_links:
        path = os.path.join(bench.work, 'chain_%d.urdf' % links)
        with open(path, 'w') as f:
            f.write(bm.chain_urdf(links))
        loops = {}
        try:
            for key, label, command in loop_variants:
                try:
                    loops[key] = BareLoop(command, [('chain', path, 'urdf', 0.0)])
                except NotMeasured as error:
                    bench.notes.append('2: %s, chain of %d links: %s' % (label, links, error))
            windows = {key: [] for key in loops}
            for _ in range(sizes.chain_windows):  # the variants alternate
                for key, loop in loops.items():
                    windows[key].append(loop.run(sizes.chain_window_s, sizes.chain_min_steps))
            for key, key_windows in windows.items():
                rates[key][links] = bm.rate(*zip(*key_windows))
                say('2 chain of %d links, %s: %.0f steps/s'
                    % (links, labels[key], rates[key][links]))
        finally:
            for loop in loops.values():
                loop.close()
    exponents = {}
    for key, by_links in rates.items():
        links = sorted(by_links)
        if len(links) < 2:
            continue
        # The fit leaves out the 1-link chain where there are enough others: its cost is mostly
        # the fixed cost of a step.
        fitted = [n for n in links if n >= 10]
        fitted = fitted if len(fitted) >= 2 else links
        exponents[key] = bm.power_law_exponent(fitted, [1 / by_links[n] for n in fitted])
        bench.add('2', '%s steps/s, chains of %s moving links; cost per step grows as '
                  'links^k' % (labels[key], ', '.join(map(str, links))),
                  '%s; k = %.2f (fit over %s links)' % (
                      ', '.join('%.0f' % by_links[n] for n in links), exponents[key],
                      ', '.join(map(str, fitted))),
                  'the same loop with 1 link', '%.0f' % by_links[links[0]],
                  by_links[links[-1]] / by_links[links[0]])
    bench.results['scaling'] = dict(rates={key: {str(n): r for n, r in v.items()}
                                           for key, v in rates.items()},
                                    exponents=exponents)
    if any(rates.values()):
        write_scaling_plot(rates, labels, exponents, os.path.join(bench.output, 'scaling.png'))
