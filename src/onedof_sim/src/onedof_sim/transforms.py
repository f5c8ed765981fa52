"""Quaternions as plain tuples (x, y, z, w), the order geometry_msgs uses. Shared by spawn_model
and the tests."""
import math


def quaternion_multiply(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def quaternion_from_rpy(roll, pitch, yaw):
    """(x, y, z, w) of Rz(yaw) * Ry(pitch) * Rx(roll): fixed-axis roll about x, then pitch about y,
    then yaw about z, as URDF and SDF mean rpy and gazebo_ros' spawn_model computes -R -P -Y (tf's
    quaternion_from_euler, static axes sxyz)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)
