"""rqt_plot's job without Qt: plot numeric fields of ROS topics against ROS time, live or headless.

Field specs use rqt_plot's syntax: `/topic/field/sub`, `field[i]` for an array element
(`/joint_states/position[0]`), `/topic/a:b` for several fields of one topic, and several specs in one
argument separated by commas; a spec naming a message (`/pos_cmd`) plots its numeric fields. The
topic part is the longest published topic that prefixes the spec. `rqt_plot` (src/rqt_plot) is this
command line under rqt_plot's name.

Samples are drawn as held values (step_path): a value holds until the next sample, the last one
until now (live) or the end of the recording, so a command published once is a horizontal line.
Each unit gets a panel of its own, its y axis labelled with it, all panels on one time axis: the
unit comes from the topic's name (UNITS: pos_cmd and jnt_pos in rad, jnt_vel in rad/s, jnt_trq in
N m); a field of another name gets a panel labelled with its name.

The pure part (parsing, field resolution, the bounded sample buffer, CSV and figure writing) is
usable on its own: write_figure() and write_csv() take {label: (times, values)} and a path.

CSV format (wide): a header `time,<label>,<label>...`, then one row per received message in time
order; a row holds the values of the fields of the topic that sent it and leaves the other columns
empty. Fields of one topic share rows. Time is in seconds of ROS time (sim time under
/use_sim_time) relative to the earliest sample: the message's header stamp when it has a nonzero one,
else the ROS time at reception.
"""
import argparse
import collections
import csv
import os
import re
import signal
import sys
import threading
import time

import roslib.message

# Field types that plot as a number; time and duration plot as seconds.
NUMERIC_TYPES = frozenset(('bool', 'byte', 'char', 'int8', 'uint8', 'int16', 'uint16', 'int32',
                           'uint32', 'int64', 'uint64', 'float32', 'float64'))
TIME_TYPES = frozenset(('time', 'duration'))
# Samples kept per field: at 100 Hz, about 17 minutes; older samples are dropped first.
DEFAULT_BUFFER_LENGTH = 100000
TIME_LABEL = 'ROS time since the first sample [s]'
ANGLE = 'angle (rad)'
RATE = 'rate (rad/s)'
TORQUE = 'torque (N m)'
# The y-axis label of each quantity the tutorial plots, by a name a series' label carries: a topic
# (/jnt_pos/data) or a word of it ('rospy PD jnt_pos'). Series of one label share a panel.
UNITS = {'pos_cmd': ANGLE, 'jnt_pos': ANGLE, 'jnt_vel': RATE, 'jnt_trq': TORQUE}
# A zoomed figure ends when every series stays within this fraction of its range of values about
# its last value, plus this fraction of that time as a margin.
SETTLED_BAND = 0.05
ZOOM_MARGIN = 0.25

_PATH_PART = re.compile(r'^([A-Za-z_][A-Za-z0-9_]*)(?:\[(\d+)\])?$')
_ARRAY_TYPE = re.compile(r'^(.*)\[(\d*)\]$')


class _TimeFields:
    """Stands in for a message class in field_accessor: a time or duration plots as seconds, or
    through its secs and nsecs fields."""

    def __init__(self, type_name, secs_type):
        self._type = type_name
        self.__slots__ = ('secs', 'nsecs')
        self._slot_types = (secs_type, 'int32')


_TIME_FIELDS = {'time': _TimeFields('time', 'uint32'), 'duration': _TimeFields('duration', 'int32')}


class PlotError(Exception):
    """A problem the user must fix (bad spec, unknown topic or field, no data); the message says
    which."""


def expand_specs(args):
    """rqt_plot's shorthand expanded: 'a,b' is two specs and '/t/x:y:z' is /t/x, /t/y, /t/z."""
    specs = []
    for arg in args:
        for spec in (s for s in arg.split(',') if s):
            if ':' not in spec:
                specs.append(spec)
                continue
            first, *more = spec.split(':')
            if '/' not in first:
                raise PlotError("'%s': the part before ':' must be topic/field" % spec)
            base = first[:first.rfind('/') + 1]
            specs.append(first)
            for field in more:
                if not field:
                    raise PlotError("'%s': empty field name after ':'" % spec)
                specs.append(base + field)
    return specs


def split_topic_field(spec, topics):
    """(topic, field path) for the longest topic among `topics` that prefixes `spec`; None if no
    topic does. `spec` and the topics are resolved (absolute) names."""
    best = None
    for topic in topics:
        if spec == topic or spec.startswith(topic.rstrip('/') + '/'):
            if best is None or len(topic) > len(best):
                best = topic
    if best is None:
        return None
    return best, spec[len(best):].strip('/')


def parse_field_path(path):
    """'pose[0]/position/x' -> [('pose', 0), ('position', None), ('x', None)]."""
    if not path:
        return []
    parts = []
    for part in path.split('/'):
        match = _PATH_PART.match(part)
        if not match:
            raise PlotError("bad field '%s' in '%s': expected name or name[index]" % (part, path))
        parts.append((match.group(1), None if match.group(2) is None else int(match.group(2))))
    return parts


def _element_type(slot_type):
    """('float64', True) for 'float64[]' or 'float64[3]', (slot_type, False) otherwise."""
    match = _ARRAY_TYPE.match(slot_type)
    return (match.group(1), True) if match else (slot_type, False)


def _fields_of(msg_class):
    return ', '.join(msg_class.__slots__) or '(none)'


def _walk_fields(msg_class, path, message_class):
    """The read steps [(name, index)] of `path` in messages of `msg_class`, and what it names:
    (steps, class, type), class None for a number. PlotError names an unknown field and the valid
    ones, a missing or extra index, a string."""
    steps = []
    current = msg_class
    current_type = msg_class._type
    parts = parse_field_path(path)
    for depth, (name, index) in enumerate(parts):
        if current is None:
            raise PlotError("'%s' has no field '%s': it is a %s" % (
                '/'.join(p for p, _ in parts[:depth]), name, current_type))
        if name not in current.__slots__:
            raise PlotError("%s has no field '%s'; its fields: %s"
                            % (current_type, name, _fields_of(current)))
        slot_type, is_array = _element_type(current._slot_types[current.__slots__.index(name)])
        if index is not None and not is_array:
            raise PlotError("field '%s' of %s is a %s, not an array: drop [%d]"
                            % (name, current_type, slot_type, index))
        if is_array and index is None:
            raise PlotError("field '%s' of %s is an array of %s: pick an element, e.g. %s[0]"
                            % (name, current_type, slot_type, name))
        steps.append((name, index))
        if slot_type in NUMERIC_TYPES:
            current, current_type = None, slot_type
        elif slot_type in TIME_TYPES:
            current, current_type = _TIME_FIELDS[slot_type], slot_type
        elif slot_type == 'string':
            raise PlotError("field '%s' of %s is a string, not a number" % (name, current_type))
        else:
            current = message_class(slot_type)
            current_type = slot_type
            if current is None:
                raise PlotError("cannot load message type %s (field '%s')" % (slot_type, name))
    return steps, current, current_type


def _is_plottable(current_type):
    return current_type in NUMERIC_TYPES or current_type in TIME_TYPES


def plottable_paths(msg_class, path, message_class=roslib.message.get_message_class):
    """The field paths that `path` stands for, as in rqt_plot: itself when it names a number, the
    message's numeric (non-array) fields when it names a message (`rqt_plot /pos_cmd` plots
    /pos_cmd/data). PlotError when it names nothing plottable."""
    _, current, current_type = _walk_fields(msg_class, path, message_class)
    if current is None or current_type in TIME_TYPES:
        return [path]
    fields = [name for name, slot_type in zip(current.__slots__, current._slot_types)
              if _is_plottable(slot_type)]
    if not fields:
        raise PlotError('%s has no numeric field to plot; its fields: %s'
                        % (current_type, _fields_of(current)))
    return ['%s/%s' % (path, name) if path else name for name in fields]


def field_accessor(msg_class, path, message_class=roslib.message.get_message_class):
    """A function msg -> float reading the field `path` of messages of `msg_class`.

    The path is checked against the message definition first: a PlotError names an unknown field
    and the valid ones, a missing or extra index, or a field that is not a number. Reading an array
    element that a message does not have raises IndexError.
    """
    steps, current, current_type = _walk_fields(msg_class, path, message_class)
    if current is not None and current_type not in TIME_TYPES:
        if not steps:
            raise PlotError('%s is a message: pick one of its fields: %s'
                            % (current_type, _fields_of(current)))
        raise PlotError("field '%s' is a %s: pick one of its fields: %s"
                        % (steps[-1][0], current_type, _fields_of(current)))

    def read(msg):
        value = msg
        for name, index in steps:
            value = getattr(value, name)
            if index is not None:
                value = value[index]
        if hasattr(value, 'to_sec'):
            return value.to_sec()
        return float(value)
    return read


def header_stamp(msg):
    """The message's header stamp in seconds, or None when it has no header or a zero stamp."""
    if not getattr(msg, '_has_header', False):
        return None
    stamp = msg.header.stamp
    if stamp.is_zero():
        return None
    return stamp.to_sec()


class SampleBuffer:
    """Thread-safe (time, value) samples per label, at most `maxlen` per label (oldest dropped),
    so memory stays bounded however long it runs."""

    def __init__(self, labels, maxlen=DEFAULT_BUFFER_LENGTH):
        if maxlen < 1:
            raise ValueError('maxlen must be >= 1')
        self._lock = threading.Lock()
        self._samples = {label: collections.deque(maxlen=maxlen) for label in labels}
        self._origin = None

    def append(self, label, t, value):
        with self._lock:
            # Header stamps can precede the reception time of a sample appended earlier.
            if self._origin is None or t < self._origin:
                self._origin = t
            self._samples[label].append((t, value))

    def first_time(self, since):
        """The time of the earliest sample from time `since` on (0 on series(since)'s axis);
        `since` when there is none."""
        with self._lock:
            return self._earliest_from(since)

    def _earliest_from(self, since):
        """first_time's answer, the lock held."""
        return min((t for samples in self._samples.values() for t, _ in samples if t >= since),
                   default=since)

    def count(self, label):
        with self._lock:
            return len(self._samples[label])

    def since_origin(self, t):
        """Time `t` on the series' time axis (0 at the earliest sample); None before any sample."""
        with self._lock:
            return None if self._origin is None else t - self._origin

    def series(self, since=None, until=None):
        """{label: (times, values)}: the samples from time `since` up to time `until`, each when
        given, times relative to the earliest of them (with since; else to the earliest sample
        ever appended)."""
        with self._lock:
            kept = {label: [(t, v) for t, v in samples
                            if (since is None or t >= since) and (until is None or t <= until)]
                    for label, samples in self._samples.items()}
            origin = (self._origin or 0.0) if since is None else self._earliest_from(since)
            return {label: ([t - origin for t, _ in samples], [v for _, v in samples])
                    for label, samples in kept.items()}


def write_csv(series, path):
    """Writes {label: (times, values)} as a wide CSV (see the module docstring)."""
    rows = collections.defaultdict(dict)
    for label, (times, values) in series.items():
        seen = collections.Counter()
        for t, value in zip(times, values):
            # A repeated time within one series gets its own row (the k-th sample at time t).
            rows[(t, seen[t])][label] = value
            seen[t] += 1
    labels = list(series)
    with open(path, 'w', newline='') as f:
        writer = csv.writer(f)
        writer.writerow(['time'] + labels)
        for t, occurrence in sorted(rows):
            row = rows[(t, occurrence)]
            writer.writerow([repr(t)] + [repr(row[label]) if label in row else ''
                                         for label in labels])


def read_csv(path):
    """The {label: (times, values)} that write_csv wrote."""
    with open(path, newline='') as f:
        reader = csv.reader(f)
        header = next(reader)
        if not header or header[0] != 'time':
            raise ValueError('%s: not a plot CSV (first column must be time)' % path)
        series = {label: ([], []) for label in header[1:]}
        for row in reader:
            t = float(row[0])
            for label, cell in zip(header[1:], row[1:]):
                if cell != '':
                    series[label][0].append(t)
                    series[label][1].append(float(cell))
    return series


def held_window(times, values, start, end):
    """The samples in [start, end), led by the value held at `start` (the last sample before it,
    moved to `start`): a command sent before the window still shows across it."""
    before = [i for i, t in enumerate(times) if t < start]
    inside = [i for i, t in enumerate(times) if start <= t < end]
    held = [before[-1]] if before and (not inside or times[inside[0]] > start) else []
    return ([start] * len(held) + [times[i] for i in inside],
            [values[i] for i in held + inside])


def step_path(times, values, until=None):
    """The vertices that draw samples as held values: each value holds as a horizontal line until
    the next sample (then a vertical jump), the last one until `until` when that is later. A
    command published once is a line, not a point; two commands are a step, not a ramp."""
    xs, ys = [], []
    for i, (t, value) in enumerate(zip(times, values)):
        if i:
            xs.append(t)
            ys.append(values[i - 1])
        xs.append(t)
        ys.append(value)
    if xs and until is not None and until > xs[-1]:
        xs.append(until)
        ys.append(ys[-1])
    return xs, ys


def unit_of(label):
    """The y-axis label (quantity and unit) UNITS gives the series `label`, from the first of its
    names (split at '/' and spaces) that UNITS knows; None when it knows none."""
    for name in re.split(r'[/\s]+', label):
        if name in UNITS:
            return UNITS[name]
    return None


def unit_panels(series):
    """{label: (times, values)} as panels [(ylabel, series)]: one per unit, labelled by it (see
    unit_of), and one per series of unknown unit, labelled by its name; in the order the series
    come, each panel's series too."""
    panels = {}
    for label, data in series.items():
        panels.setdefault(unit_of(label) or label, {})[label] = data
    return list(panels.items())


def settling_time(times, values, band):
    """The time of the last sample further than `band` from the last value (the first sample's
    time when none is): from then on the series stays within the band. None without samples."""
    if not times:
        return None
    settled = times[0]
    for t, value in zip(times, values):
        if abs(value - values[-1]) > band:
            settled = t
    return settled


def motion_span(series, band=SETTLED_BAND, margin=ZOOM_MARGIN):
    """(start, end) of where {label: (times, values)} moves: from the earliest sample until the
    slowest series has settled within `band` times its range of values about its last value (see
    settling_time), plus `margin` times that span. None when nothing moves."""
    starts, ends = [], []
    for times, values in series.values():
        if times:
            starts.append(min(times))
            ends.append(settling_time(times, values, band * (max(values) - min(values))))
    if not ends or max(ends) <= min(starts):
        return None
    start = min(starts)
    return start, max(ends) + margin * (max(ends) - start)


def _draw_series(ax, series, title=None, xlabel=TIME_LABEL, ylabel=None, until=None,
                 legend=True):
    lines = {label: ax.plot(*step_path(times, values, until), label=label)[0]
             for label, (times, values) in series.items()}
    if xlabel:
        ax.set_xlabel(xlabel)
    if ylabel:
        ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.grid(True)
    if series and legend:
        ax.legend(loc='best')
    return lines


def _figure_size(panel_count, small_panel_count=0):
    """Width and height (inches) that give every panel room for its labels."""
    return 10, max(6.0, 1.2 + 2.4 * panel_count + 1.6 * small_panel_count)


def _draw_panels(figure, panels, title, xlabel, until, small_panel=False):
    """Axes stacked in `figure`, one per (ylabel, series) of `panels` on a shared time axis (the
    title over the first, the time label under the last), and a smaller one below them when
    `small_panel`; returns (the panels' axes, the small one or None, {label: line})."""
    grid = figure.add_gridspec(len(panels) + small_panel, 1,
                               height_ratios=[3] * len(panels) + [2] * small_panel)
    axes, lines, first = [], {}, None
    for index, (ylabel, series) in enumerate(panels):
        ax = figure.add_subplot(grid[index], sharex=first)
        first = first or ax
        last = index == len(panels) - 1
        lines.update(_draw_series(ax, series, title if index == 0 else None,
                                  xlabel if last else None, ylabel, until))
        # The time's numbers once, under the last panel of the shared axis.
        ax.tick_params(labelbottom=last)
        axes.append(ax)
    return axes, figure.add_subplot(grid[-1]) if small_panel else None, lines


def _zoom_span(panels, until):
    """motion_span of every series of `panels`; None when they move until the run's end (its last
    sample or `until`)."""
    series = [data for _, panel_series in panels for data in panel_series.values()]
    span = motion_span(dict(enumerate(series)))
    ends = [max(times) for times, _ in series if times] + ([] if until is None else [until])
    return span if span is not None and span[1] < max(ends) else None


def make_figure(series, title=None, xlabel=TIME_LABEL, ylabel=None, size=None, until=None):
    """A matplotlib Figure of {label: (times, values)}, one line per label, each sample held until
    the next and the last until `until` (see step_path): one panel per unit (see unit_panels), or
    one panel labelled `ylabel` when it is given; independent of pyplot (so saving it works on any
    backend, headless included)."""
    panels = [(ylabel, series)] if ylabel else unit_panels(series)
    return make_panels_figure(panels, title, xlabel, size, until)


def make_panels_figure(panels, title=None, xlabel=TIME_LABEL, size=None, until=None, zoom=False):
    """make_figure's figure with one panel per (ylabel, series) of `panels`, stacked on a shared
    time axis: the title over the first, the time label under the last.

    With zoom, the panels show only where the series move (motion_span of all of them) and a
    smaller panel below shows the whole run of the first panel's series, the zoomed span shaded;
    when they move until the end, the panels show the whole run and there is no smaller one."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    span = _zoom_span(panels, until) if zoom else None
    figure = Figure(figsize=size or _figure_size(len(panels), span is not None))
    FigureCanvasAgg(figure)
    axes, whole_run, _ = _draw_panels(figure, panels, title, xlabel, until, span is not None)
    if span is not None:
        axes[0].set_xlim(*span)
        ylabel, series = panels[0]
        _draw_series(whole_run, series, xlabel=xlabel, ylabel=ylabel, until=until, legend=False)
        whole_run.axvspan(*span, color='0.85', zorder=0)
        whole_run.set_title('the whole run (shaded: the span drawn above)', loc='left',
                            fontsize='medium')
    figure.tight_layout()
    return figure


def write_figure(series, path, title=None, xlabel=TIME_LABEL, ylabel=None, until=None):
    """Writes make_figure's figure of {label: (times, values)} to `path` (format from its
    extension)."""
    make_figure(series, title, xlabel, ylabel, until=until).savefig(path, dpi=100)


def write_panels_figure(panels, path, title=None, xlabel=TIME_LABEL, size=None, until=None,
                        zoom=False):
    """Writes make_panels_figure's figure of [(ylabel, series)] to `path`."""
    make_panels_figure(panels, title, xlabel, size, until, zoom).savefig(path, dpi=100)


# ---- ROS side: find the topics, subscribe, record or show ----

class TopicRecorder:
    """Subscribes to the topics of the given resolved specs and buffers their fields' values."""

    def __init__(self, specs, buffer_length=DEFAULT_BUFFER_LENGTH, timeout=10.0):
        self.message_counts = collections.Counter()
        self.first_reception = None  # ROS time (s) at which the first message arrived
        self.first_receptions = {}  # topic -> ROS time (s) at which its first message arrived
        # topic -> [(label, read, msg_class)]; one label per plotted field, in the order given.
        self._fields, self.labels = self._resolve(specs, timeout)
        self.topics = list(self._fields)
        self._timeout = timeout
        self.buffer = SampleBuffer(self.labels, buffer_length)
        self._missing_index = set()
        self._subscribers = []

    @staticmethod
    def _resolve(specs, timeout):
        import rosgraph
        import rospy
        master = rosgraph.Master(rospy.get_name())
        deadline = time.monotonic() + timeout
        while True:
            types = dict(master.getPublishedTopics('/'))
            splits = {spec: split_topic_field(spec, types) for spec in specs}
            unmatched = [spec for spec, split in splits.items() if split is None]
            if not unmatched:
                break
            if time.monotonic() > deadline or rospy.is_shutdown():
                raise PlotError('no published topic matches %s (waited %g s; published: %s)' % (
                    ', '.join(unmatched), timeout, ', '.join(sorted(types)) or 'none'))
            time.sleep(0.1)
        fields = collections.defaultdict(list)
        labels = []
        for spec, (topic, path) in splits.items():
            msg_class = roslib.message.get_message_class(types[topic])
            if msg_class is None:
                raise PlotError('%s: cannot load message type %s of %s'
                                % (spec, types[topic], topic))
            try:
                # A spec naming a message stands for its numeric fields, as in rqt_plot.
                for field in plottable_paths(msg_class, path):
                    label = topic.rstrip('/') + '/' + field
                    if label not in labels:
                        labels.append(label)
                        fields[topic].append((label, field_accessor(msg_class, field), msg_class))
            except PlotError as error:
                raise PlotError('%s: %s' % (spec, error)) from None
        return fields, labels

    def start(self):
        """Subscribes once ROS time is known: under /use_sim_time rospy reads 0 until its first
        /clock message, and a sample stamped then would sit at 0 on the time axis."""
        import rospy
        if rospy.get_param('/use_sim_time', False):
            from rosgraph_msgs.msg import Clock
            try:
                # rospy's own /clock callback runs before this one on the same message.
                rospy.wait_for_message('/clock', Clock, timeout=self._timeout)
            except rospy.ROSException:
                raise PlotError('/use_sim_time is set and no /clock message came in %g s '
                                '(is the simulator running?)' % self._timeout) from None
        for topic, fields in self._fields.items():
            self._subscribers.append(rospy.Subscriber(
                topic, fields[0][2], self._on_message, callback_args=topic, queue_size=100))

    def stop(self):
        for subscriber in self._subscribers:
            subscriber.unregister()
        self._subscribers = []

    def _on_message(self, msg, topic):
        import rospy
        received = rospy.get_rostime().to_sec()
        if self.first_reception is None:
            self.first_reception = received
        self.first_receptions.setdefault(topic, received)
        t = header_stamp(msg)
        if t is None:
            t = received
        self.message_counts[topic] += 1
        for label, read, _ in self._fields[topic]:
            try:
                value = read(msg)
            except IndexError:
                if label not in self._missing_index:
                    self._missing_index.add(label)
                    rospy.logwarn('%s: a message on %s has no such element; skipping those',
                                  label, topic)
                continue
            self.buffer.append(label, t, value)

    def check_received(self, span):
        """PlotError naming every topic that sent nothing and every field that got no sample;
        `span` says over what time, for the message."""
        problems = ['no message on %s in %s' % (topic, span)
                    for topic in self._fields if not self.message_counts[topic]]
        problems += ['%s: no message on %s had that element' % (label, topic)
                     for topic, fields in self._fields.items() if self.message_counts[topic]
                     for label, _, _ in fields if not self.buffer.count(label)]
        if problems:
            raise PlotError('; '.join(problems))


def record(recorder, duration, timeout):
    """Records `duration` seconds of ROS time from when every topic has sent its first message
    (each is connected to on its own, some later than others: every series then covers the
    whole recording); returns (start, end), the ROS times the recording covers (what arrived
    earlier or later is not part of it). PlotError when a topic sends nothing within `timeout`
    wall seconds, or when ROS time stands still that long."""
    import rospy
    recorder.start()
    topics = len(recorder.topics)
    try:
        deadline = time.monotonic() + timeout
        while len(recorder.first_receptions) < topics:
            if time.monotonic() > deadline or rospy.is_shutdown():
                recorder.check_received('the first %g s' % timeout)
                break  # each topic has spoken by now
            time.sleep(0.01)
        start = max(recorder.first_receptions.values())
        last_time, last_progress = start, time.monotonic()
        while not rospy.is_shutdown():
            now = rospy.get_rostime().to_sec()
            if now - start >= duration:
                now = start + duration
                break
            if now != last_time:
                last_time, last_progress = now, time.monotonic()
            elif time.monotonic() - last_progress > timeout:
                raise PlotError('ROS time stood still at %.3f s for %g s (is /clock published?)'
                                % (now, timeout))
            time.sleep(0.01)
    finally:
        recorder.stop()
    recorder.check_received('%g s of ROS time' % duration)
    return start, now


def show_live(recorder, title, start_paused=False, refresh_hz=10.0):
    """A window redrawn at `refresh_hz` until it is closed, a panel per unit as in the written
    figure; every value holds until the next and the last until now. Space or p pauses and
    resumes the drawing (recording goes on)."""
    import matplotlib.pyplot as plt
    import rospy
    from matplotlib.animation import FuncAnimation
    if plt.get_backend().lower() in ('agg', 'pdf', 'ps', 'svg', 'cairo', 'template'):
        raise PlotError('matplotlib has no interactive backend here (%s): record headless with '
                        '--duration S --png F --csv F' % plt.get_backend())
    panels = unit_panels({label: ([], []) for label in recorder.labels})
    figure = plt.figure(figsize=_figure_size(len(panels)))
    figure.canvas.manager.set_window_title(title)
    axes, _, lines = _draw_panels(figure, panels, None, TIME_LABEL, None)
    figure.tight_layout()
    paused = [start_paused]
    # Ctrl-C: Python raises KeyboardInterrupt wherever the main thread is, and inside a Tk
    # callback (a redraw, much of the time on a busy machine) tkinter reports it and carries on
    # with the window open. So the handler only notes it, and the next frame closes the window.
    interrupted = []

    def on_key(event):
        if event.key in (' ', 'p'):
            paused[0] = not paused[0]

    def update(_frame):
        if interrupted:
            plt.close(figure)
            return []
        if paused[0]:
            return []
        now = recorder.buffer.since_origin(rospy.get_rostime().to_sec())
        for label, (times, values) in recorder.buffer.series().items():
            lines[label].set_data(*step_path(times, values, until=now))
        for ax in axes:
            ax.relim()
            ax.autoscale_view()
        return list(lines.values())

    figure.canvas.mpl_connect('key_press_event', on_key)
    recorder.start()
    animation = FuncAnimation(figure, update, interval=1000.0 / refresh_hz,
                              cache_frame_data=False)
    previous_handler = signal.signal(signal.SIGINT, lambda *_: interrupted.append(True))
    try:
        plt.show()
    finally:
        signal.signal(signal.SIGINT, previous_handler)
        del animation
        recorder.stop()
    if interrupted:
        raise KeyboardInterrupt


def parse_args(argv, prog='rosrun onedof_sim plot'):
    if prog == 'rqt_plot':
        description = ("This workspace's plotter (rosrun onedof_sim plot) standing in for "
                       "rqt_plot, which is not packaged here: rqt_plot's command line, a "
                       "matplotlib window instead of rqt's. ")
    else:
        description = 'Plots numeric fields of ROS topics against ROS time, in place of rqt_plot. '
    parser = argparse.ArgumentParser(
        prog=prog,
        description=description +
        "Every value is drawn held until the next one (a command published once is a "
        "horizontal line up to now). Without --png/--csv it opens a live window (space or p "
        "pauses it); with them it records --duration seconds of ROS time headless and writes "
        "the files.",
        epilog='example: %s /jnt_pos/data /jnt_trq/data /jnt_vel/data /pos_cmd' % prog)
    parser.add_argument('fields', nargs='+', metavar='TOPIC/FIELD',
                        help="rqt_plot syntax: /topic/field, /topic/array[i], /topic/a:b "
                             "(fields a and b of /topic), a,b (two specs); /topic alone plots "
                             "all its numeric fields")
    parser.add_argument('-P', '--pause', action='store_true', dest='start_paused',
                        help='start the live window paused (as rqt_plot -P)')
    parser.add_argument('-e', '--empty', action='store_true', dest='start_empty',
                        help='as rqt_plot -e: start without restoring topics of a previous '
                             'session (this plotter never restores them)')
    parser.add_argument('--duration', type=float, metavar='S',
                        help='record S seconds of ROS time from the first message received '
                             '(required with --png/--csv)')
    parser.add_argument('--png', metavar='F', help='write the figure to F (headless)')
    parser.add_argument('--csv', metavar='F', help='write the samples to F (headless)')
    parser.add_argument('--title', help='figure title')
    parser.add_argument('--timeout', type=float, default=10.0, metavar='T',
                        help='wall seconds to wait for the topics to appear, for their first '
                             'message and for ROS time to move (default %(default)s)')
    parser.add_argument('--buffer', type=int, default=DEFAULT_BUFFER_LENGTH, metavar='N',
                        help='samples kept per field, oldest dropped (default %(default)s)')
    args = parser.parse_args(argv)
    headless = args.png is not None or args.csv is not None
    if headless and (args.duration is None or not args.duration > 0):
        parser.error('--png/--csv record headless: give --duration S (S > 0)')
    if args.duration is not None and not headless:
        parser.error('--duration records headless: give --png F and/or --csv F')
    if not args.timeout > 0 or args.buffer < 1:
        parser.error('--timeout must be > 0 and --buffer >= 1')
    return args, headless


def main(argv=None, prog='rosrun onedof_sim plot'):
    """The command line of `rosrun onedof_sim plot` and, with prog='rqt_plot', of rqt_plot."""
    import rospy
    argv = rospy.myargv(sys.argv if argv is None else argv)[1:]
    args, headless = parse_args(argv, prog)
    name = prog.split()[-1]
    if headless:
        import matplotlib
        matplotlib.use('Agg')
    elif not (os.environ.get('DISPLAY') or os.environ.get('WAYLAND_DISPLAY')):
        sys.stderr.write('%s: no display: record headless with --duration S --png F --csv F\n'
                         % name)
        return 2
    rospy.init_node(name, anonymous=True, disable_signals=True)
    try:
        specs = [rospy.resolve_name(spec) for spec in expand_specs(args.fields)]
        recorder = TopicRecorder(specs, args.buffer, args.timeout)
        if not headless:
            show_live(recorder, args.title or prog, args.start_paused)
            return 0
        start, end = record(recorder, args.duration, args.timeout)
        series = recorder.buffer.series(since=start, until=end)
        if args.png:
            write_figure(series, args.png, title=args.title,
                         until=end - recorder.buffer.first_time(start))
        if args.csv:
            write_csv(series, args.csv)
        print('%s: %s samples of %s over %g s of ROS time -> %s' % (
            name, sum(len(t) for t, _ in series.values()), ', '.join(recorder.labels),
            args.duration, ', '.join(f for f in (args.png, args.csv) if f)))
        return 0
    except PlotError as error:
        sys.stderr.write('%s: error: %s\n' % (name, error))
        return 1
    except KeyboardInterrupt:
        return 130
    finally:
        rospy.signal_shutdown('plot finished')
