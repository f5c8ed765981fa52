"""Gazebo's right-click View > Collisions, Joints, Center of Mass and Inertia of single models, for
the simulator's rviz view: the simulator draws each of these views for every model at once (its
marker topics, which the world's View menu ticks on as whole displays); a model's own view is that
model's markers of the view, relayed on one topic, MODEL_VIEW_MARKERS, which world.rviz's
"Model views" display shows. A relayed marker's namespace is the model's name and the view's
("near/Collisions"), so that the display has a checkbox for each.

A view's topic is subscribed to only while some model is in that view: the simulator makes a
view's markers only for subscribers. A model taken out of a view, or gone from the world, has its
relayed markers deleted at once; a marker the simulator deletes is deleted here too.
"""
import threading

MODEL_VIEW_MARKERS = '/gazebo_window/model_view_markers'
# Gazebo's titles, in its menu's order, and the simulator's topic of each view.
MARKER_VIEW_MODES = (('Collisions', '/gazebo/collision_markers'),
                     ('Joints', '/gazebo/joint_markers'),
                     ('Center of Mass', '/gazebo/com_markers'),
                     ('Inertia', '/gazebo/inertia_markers'))


def relayed_namespace(model, mode):
    return '%s/%s' % (model, mode)


class ModelMarkerViews:
    """The models in each view of MARKER_VIEW_MODES, and the relay of their markers.
    `publisher` is a visualization_msgs/MarkerArray publisher on MODEL_VIEW_MARKERS;
    `subscribe(topic, callback)` subscribes to a MarkerArray topic and returns what has an
    unregister()."""

    def __init__(self, publisher, subscribe):
        self.modes = [mode for mode, _ in MARKER_VIEW_MODES]
        self.topics = dict(MARKER_VIEW_MODES)
        self.publisher = publisher
        self.subscribe = subscribe
        self.lock = threading.Lock()
        self.models = {mode: set() for mode in self.modes}
        self.subscriptions = {}  # mode -> its subscription, while a model is in it
        self.shown = {}  # (model, mode) -> the ids relayed and not deleted since

    def is_on(self, mode, name):
        with self.lock:
            return name in self.models[mode]

    def toggle(self, mode, name):
        """Model `name` into view `mode`, or out of it; whether it is in it now."""
        with self.lock:
            models = self.models[mode]
            if name in models:
                models.discard(name)
                self._publish(self._take_shown(name, mode))
                unsubscribe = not models and self.subscriptions.pop(mode, None)
                on = False
            else:
                models.add(name)
                unsubscribe = None
                if mode not in self.subscriptions:
                    self.subscriptions[mode] = self.subscribe(
                        self.topics[mode], lambda array, mode=mode: self.on_markers(mode, array))
                on = True
        if unsubscribe:
            unsubscribe.unregister()
        return on

    def forget(self, name):
        """A model gone from the world: in no view, its relayed markers deleted."""
        for mode in self.modes:
            if self.is_on(mode, name):
                self.toggle(mode, name)

    def on_markers(self, mode, array):
        """The simulator's markers of view `mode`: those of the models in it, relayed (published
        under the lock, so that a model's markers and their deletion go out in order)."""
        relayed = []
        with self.lock:
            models = self.models[mode]
            for marker in array.markers:
                if marker.ns not in models:
                    continue
                shown = self.shown.setdefault((marker.ns, mode), set())
                if marker.action == marker.DELETE:
                    shown.discard(marker.id)
                elif marker.action == marker.ADD:
                    shown.add(marker.id)
                else:
                    continue
                marker.ns = relayed_namespace(marker.ns, mode)
                relayed.append(marker)
            self._publish(relayed)

    def _take_shown(self, name, mode):
        """DELETE markers for what was relayed of model `name` in view `mode` (lock held)."""
        from visualization_msgs.msg import Marker
        gone = []
        for marker_id in sorted(self.shown.pop((name, mode), ())):
            marker = Marker(ns=relayed_namespace(name, mode), id=marker_id, action=Marker.DELETE)
            marker.header.frame_id = 'world'
            gone.append(marker)
        return gone

    def _publish(self, markers):
        from visualization_msgs.msg import MarkerArray
        if markers:
            self.publisher.publish(MarkerArray(markers=markers))
