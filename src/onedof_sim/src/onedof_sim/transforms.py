"""Rigid transforms as plain tuples: (position (x, y, z), quaternion (x, y, z, w)), the order
pybullet and geometry_msgs use. Shared by the pybullet engine, spawn_model and the tests."""
import math


def quaternion_multiply(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def quaternion_conjugate(q):
    return (-q[0], -q[1], -q[2], q[3])


def rotate(q, v):
    x, y, z = quaternion_multiply(quaternion_multiply(q, (v[0], v[1], v[2], 0.0)),
                                  quaternion_conjugate(q))[:3]
    return (x, y, z)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def compose(a, b):
    """The transform a * b: b expressed in a's parent frame."""
    return add(a[0], rotate(a[1], b[0])), quaternion_multiply(a[1], b[1])


def invert(t):
    q_inv = quaternion_conjugate(t[1])
    return tuple(-c for c in rotate(q_inv, t[0])), q_inv


def quaternion_from_rpy(roll, pitch, yaw):
    """(x, y, z, w) of Rz(yaw) * Ry(pitch) * Rx(roll): fixed-axis roll about x, then pitch about y,
    then yaw about z, as URDF and SDF mean rpy and gazebo_ros' spawn_model computes -R -P -Y (tf's
    quaternion_from_euler, static axes sxyz)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


def normalized(q):
    n = math.sqrt(sum(c * c for c in q))
    return tuple(c / n for c in q)
