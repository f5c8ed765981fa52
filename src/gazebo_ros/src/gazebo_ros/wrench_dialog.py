"""Gazebo's "Apply Force/Torque" dialog for one model, opened from its handle's right-click menu
(gazebo_ros.model_handles): the link, the force (N) and torque (N m) in the link's frame, the
point the force acts at (m, from the link's origin, in its frame) and the duration (s of sim
time, from now); Apply sends them through /gazebo/apply_body_wrench, and the dialog stays open
for another, as Gazebo's does. What the simulator answers shows under the fields.

    python3 -m gazebo_ros.wrench_dialog MODEL
"""
import sys

APPLY_BODY_WRENCH = '/gazebo/apply_body_wrench'
GET_MODEL_PROPERTIES = '/gazebo/get_model_properties'
TITLE = 'Apply Force/Torque: %s'
# The fields, in their tab order after the link: (label, name) of each number.
FIELDS = (('Force X (N)', 'fx'), ('Force Y (N)', 'fy'), ('Force Z (N)', 'fz'),
          ('Torque X (N m)', 'tx'), ('Torque Y (N m)', 'ty'), ('Torque Z (N m)', 'tz'),
          ('Point X (m)', 'px'), ('Point Y (m)', 'py'), ('Point Z (m)', 'pz'),
          ('Duration (s)', 'duration'))


def wrench_request(link, values):
    """The ApplyBodyWrenchRequest of `values` ({field name: float}) on `link` (model::link),
    starting now."""
    import rospy
    from gazebo_msgs.srv import ApplyBodyWrenchRequest
    request = ApplyBodyWrenchRequest(body_name=link, reference_frame=link)
    request.reference_point.x, request.reference_point.y, request.reference_point.z = (
        values['px'], values['py'], values['pz'])
    force, torque = request.wrench.force, request.wrench.torque
    force.x, force.y, force.z = values['fx'], values['fy'], values['fz']
    torque.x, torque.y, torque.z = values['tx'], values['ty'], values['tz']
    request.start_time = rospy.Time(0)
    request.duration = rospy.Duration.from_sec(values['duration'])
    return request


def main(argv):
    import rospy
    from gazebo_msgs.srv import ApplyBodyWrench, GetModelProperties
    from python_qt_binding.QtWidgets import (QApplication, QComboBox, QDialog, QFormLayout,
                                             QLabel, QLineEdit, QPushButton)
    argv = rospy.myargv(argv)
    if len(argv) != 2:
        sys.stderr.write('usage: python3 -m gazebo_ros.wrench_dialog MODEL\n')
        return 2
    model = argv[1]
    rospy.init_node('gazebo_wrench_dialog', anonymous=True)
    app = QApplication([argv[0]])
    dialog = QDialog()
    dialog.setWindowTitle(TITLE % model)
    form = QFormLayout(dialog)
    links = QComboBox()
    try:
        rospy.wait_for_service(GET_MODEL_PROPERTIES, timeout=10)
        properties = rospy.ServiceProxy(GET_MODEL_PROPERTIES, GetModelProperties)(model)
        bodies = properties.body_names if properties.success else []
        status_text = '' if properties.success else properties.status_message
    except (rospy.ROSException, rospy.ServiceException) as error:
        bodies, status_text = [], 'cannot list the links of %s: %s' % (model, error)
    links.addItems(['%s::%s' % (model, body) for body in bodies])
    form.addRow('Link', links)
    edits = {}
    for label, name in FIELDS:
        edits[name] = QLineEdit('0')
        form.addRow(label, edits[name])
    apply_button = QPushButton('Apply')
    apply_button.setDefault(True)
    form.addRow(apply_button)
    status = QLabel(status_text)
    form.addRow(status)
    apply_wrench = rospy.ServiceProxy(APPLY_BODY_WRENCH, ApplyBodyWrench)

    def apply():
        try:
            values = {name: float(edit.text()) for name, edit in edits.items()}
        except ValueError:
            status.setText('every field takes a number')
            return
        if not links.currentText():
            status.setText('%s has no link to push' % model)
            return
        try:
            result = apply_wrench(wrench_request(links.currentText(), values))
        except (rospy.ROSException, rospy.ServiceException) as error:
            status.setText('%s: %s' % (APPLY_BODY_WRENCH, error))
            return
        status.setText(result.status_message)
        rospy.loginfo('wrench dialog: %s on %s: %s', APPLY_BODY_WRENCH, links.currentText(),
                      result.status_message)
    apply_button.clicked.connect(apply)
    dialog.finished.connect(app.quit)
    dialog.show()
    edits['fx'].setFocus()
    edits['fx'].selectAll()
    # Qt's loop does not see rospy's shutdown: a timer lets a SIGINT end it.
    from python_qt_binding.QtCore import QTimer
    timer = QTimer()
    timer.timeout.connect(lambda: rospy.is_shutdown() and app.quit())
    timer.start(200)
    return app.exec_()


if __name__ == '__main__':
    sys.exit(main(sys.argv))
