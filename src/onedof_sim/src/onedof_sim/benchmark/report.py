"""The benchmarks' arithmetic and their report: plain functions, no ROS (the item modules of
onedof_sim.benchmark measure).

Every figure in the report is set against something run alongside it on the same machine in the
same run (a bare loop, a bare service, the wall clock), and the claim is the ratio.
"""
import collections
import math
import re

# One row of the report. met: True / False against the aim, None when the row has no aim.
Row = collections.namedtuple('Row', 'item measured figure against against_figure ratio aim met')


def percentile(values, q):
    """The q-th percentile (0..100) with linear interpolation between ranks (numpy's default)."""
    if not values:
        raise ValueError('percentile of no values')
    ordered = sorted(values)
    position = (len(ordered) - 1) * q / 100.0
    low = math.floor(position)
    high = min(low + 1, len(ordered) - 1)
    return ordered[low] + (ordered[high] - ordered[low]) * (position - low)


def rate(count, seconds):
    """Events per second over windows: total count / total time, so long windows weigh more."""
    return sum(count) / sum(seconds)


def windowed_rtf(wall, sim, window=1.0):
    """Real-time factors of consecutive windows of at least `window` wall seconds, between the
    (wall, sim) samples that open and close each window; the tail shorter than a window is left
    out."""
    factors = []
    opening = 0
    for i in range(1, len(wall)):
        if wall[i] - wall[opening] >= window:
            factors.append((sim[i] - sim[opening]) / (wall[i] - wall[opening]))
            opening = i
    return factors


def mean_rtf(wall, sim):
    return (sim[-1] - sim[0]) / (wall[-1] - wall[0])


def missed_periods(times, period):
    """Periods between the first and the last time in which no time falls: each time is put in
    the slot round((t - t0) / period). A late iteration that catches up (13 ms then 7 ms at 100 Hz)
    misses nothing; a slot with nothing in it is a miss."""
    if not times:
        return 0
    slots = {round((t - times[0]) / period) for t in times}
    return max(slots) + 1 - len(slots)


def period_jitter(times, period):
    """|interval - period| of each interval between consecutive times."""
    return [abs(b - a - period) for a, b in zip(times, times[1:])]


def power_law_exponent(xs, ys):
    """k of the least-squares fit y = c x^k on a log-log scale."""
    if len(xs) < 2:
        raise ValueError('a fit needs two points at least')
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return (sum((a - mx) * (b - my) for a, b in zip(lx, ly))
            / sum((a - mx) ** 2 for a in lx))


def cpu_model(cpuinfo_text):
    """The processor's model name in /proc/cpuinfo."""
    for line in cpuinfo_text.splitlines():
        key, _, value = line.partition(':')
        if key.strip() == 'model name':
            return value.strip()
    return 'unknown'


# Geometry of the chain benchmark: links of this length hang from a base high enough that the
# chain, started horizontal, never reaches the ground (the cost is then the articulation alone).
CHAIN_LINK_LENGTH = 0.1
CHAIN_LINK_MASS = 0.1
CHAIN_LINK_RADIUS = 0.02


def chain_urdf(links):
    """A URDF chain of `links` moving links, each on a revolute joint (axis y) under the one
    before, hanging from a base fixed to the world; the first joint turns the chain horizontal."""
    length, mass, radius = CHAIN_LINK_LENGTH, CHAIN_LINK_MASS, CHAIN_LINK_RADIUS
    lateral = mass * (3 * radius ** 2 + length ** 2) / 12
    axial = mass * radius ** 2 / 2
    height = links * length + 0.5
    parts = ['<?xml version="1.0"?>', '<robot name="chain_%d">' % links, '  <link name="world"/>',
             '  <joint name="anchor" type="fixed"><parent link="world"/><child link="base"/>'
             '<origin xyz="0 0 %g"/></joint>' % height,
             '  <link name="base"><inertial><mass value="1"/>'
             '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
             '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>']
    parent = 'base'
    for i in range(1, links + 1):
        # The first joint sits on the base with the chain turned horizontal; the others at the
        # far end of their parent link.
        origin = '<origin xyz="0 0 0" rpy="0 1.5707963 0"/>' if i == 1 else \
            '<origin xyz="0 0 %g"/>' % -length
        parts.append(
            '  <joint name="joint%d" type="revolute"><parent link="%s"/><child link="link%d"/>'
            '%s<axis xyz="0 1 0"/><limit lower="-3.1" upper="3.1" effort="100" velocity="100"/>'
            '</joint>' % (i, parent, i, origin))
        parts.append(
            '  <link name="link%d"><inertial><origin xyz="0 0 %g"/><mass value="%g"/>'
            '<inertia ixx="%g" ixy="0" ixz="0" iyy="%g" iyz="0" izz="%g"/></inertial>'
            '<collision><origin xyz="0 0 %g"/><geometry><cylinder radius="%g" length="%g"/>'
            '</geometry></collision></link>'
            % (i, -length / 2, mass, lateral, lateral, axial, -length / 2, radius, length))
        parent = 'link%d' % i
    parts.append('</robot>')
    return '\n'.join(parts) + '\n'


PERF_LINE = re.compile(r'^\s*([\d.]+)%\s+(\S+)(?:\s+\[[.kg]\]\s+(.*?))?\s*$')


def perf_report_shares(text):
    """[(percent, shared object, symbol or None)] of the lines of `perf report --stdio
    --no-children -g none --sort dso,sym` (or --sort dso), in report order."""
    shares = []
    for line in text.splitlines():
        match = PERF_LINE.match(line)
        if match and not line.lstrip().startswith('#'):
            shares.append((float(match.group(1)), match.group(2), match.group(3)))
    return shares


def collapsed_stack_shares(text):
    """{frame: (self share, inclusive share)} of collapsed stacks ("outer;...;inner COUNT" per
    line, as `py-spy record --format raw` writes). A frame is "function (file)": line numbers
    are dropped so that a function counts once, wherever in it the samples fell."""
    self_counts, inclusive_counts, total = {}, {}, 0
    for line in text.splitlines():
        stack, _, count = line.rpartition(' ')
        if not stack or not count.isdigit():
            continue
        count = int(count)
        total += count
        frames = [re.sub(r'\((?:.*/)?([^/]*?)(?::\d+)?\)$', r'(\1)', frame.strip())
                  for frame in stack.split(';')]
        for frame in set(frames):
            inclusive_counts[frame] = inclusive_counts.get(frame, 0) + count
        self_counts[frames[-1]] = self_counts.get(frames[-1], 0) + count
    if not total:
        return {}
    return {frame: (self_counts.get(frame, 0) / total, inclusive / total)
            for frame, inclusive in inclusive_counts.items()}


def ratio(value, reference):
    return value / reference if reference else math.nan


def format_ratio(value):
    return '—' if value is None or math.isnan(value) else '%.2f' % value


def one_line(value):
    """Text on one line without terminal escapes (they come with messages quoted from logs)."""
    text = re.sub(r'\x1b\][^\x07]*\x07|\x1b\[[0-9;]*[A-Za-z]', '', str(value))
    return ' '.join(text.split())


def markdown_cell(value):
    return one_line(value).replace('|', '\\|')


def render_table(rows, machine, date, notes=()):
    """The report in Markdown: the machine, one line per row, then the notes."""
    load = ('; load average (1 min) at the start and the end of the run %s'
            % machine['load'] if machine.get('load') else '')
    lines = ['# onedof_sim benchmarks', '',
             'Machine: %s, %d cores%s; %s. Each row is measured side by side with what it is '
             'compared against, in one run, alternating between the two where both cannot run '
             'at once; the ratio is the claim, the bare figures depend on the machine.'
             % (machine['cpu'], machine['cores'], load, date), '',
             '| # | measured | figure | compared against | its figure | ratio | aim | met |',
             '|---|---|---|---|---|---|---|---|']
    for row in rows:
        met = {True: 'met', False: '**not met**', None: '—'}[row.met]
        cells = (row.item, row.measured, row.figure, row.against, row.against_figure,
                 format_ratio(row.ratio), row.aim or '—', met)
        lines.append('| ' + ' | '.join(markdown_cell(cell) for cell in cells) + ' |')
    if notes:
        lines += ['', '## Notes', '']
        lines += ['- ' + one_line(note) for note in notes]
    return '\n'.join(lines) + '\n'
