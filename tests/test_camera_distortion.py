"""Lens distortion over real ROS, on every engine: cameras with a <distortion> side by side with a
pinhole camera, 1 m before a wall of red and blue tiles 0.1 m square (its left edge a straight
vertical line at y = 0.6).
- Gazebo's own distortion tests, with their lenses (barrel k1 = k2 = k3 = -0.1, pincushion +0.1,
  square images with f equal to the width) and <autoDistortion>: CameraInfo's D is the lens's
  (k1, k2, p1, p2, k3); undistorting the image with CameraInfo's K and D (OpenCV's undistort,
  done here in numpy) gives back the pinhole camera's image, and D is where the difference is
  least, each coefficient moved by 0.01 either way making it larger.
- A lens as a calibration finds one (640 x 480, f 467 px, k1 -0.25, k2 0.08, tangential terms):
  the wall's straight edge bends in the image as the model says, to within a pixel, by ten
  pixels and more, and undistorting its points with CameraInfo's K and D puts them back on one
  straight line, within a pixel, where the pinhole camera sees it.
The difference-based check of Gazebo's tests needs their large image: at 400 x 400 pixels a
coefficient moved by 0.01 shifts the tiles' edges by less than the interpolation blurs them.
The square cameras see only the wall; the wide one sees past its edge, and the edge is found
against the sky's uniform grey: its world leaves the ground out (tests/worlds/without_ground.world,
as Gazebo lets a world do), since below the horizon the ground is another grey whose far edge, bent
by the lens, crosses the rows."""
import math
import os

import numpy
import pytest

from conftest import ENGINES
from test_camera import hear_periods
from test_camera_formats import camera_sensor, start

GREY = 178  # the background's channels: Gazebo's 0.7 grey
SQUARE, SQUARE_FOV = 1000, 2 * math.atan(0.5)  # Gazebo's tests' cameras: f = 1000 px, the width
WIDE, HIGH, WIDE_FOV = 640, 480, 1.2
WALL_X, WALL_LEFT_Y, LENS_Z, TILE = 1.0, 0.6, 0.5, 0.1
# Each lens: its (k1, k2, p1, p2, k3), as CameraInfo's D orders them.
BARREL = (-0.1, -0.1, 0.0, 0.0, -0.1)
PINCUSHION = (0.1, 0.1, 0.0, 0.0, 0.1)
CALIBRATED = (-0.25, 0.08, 0.002, -0.0015, 0.0)
WITHOUT_GROUND = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'worlds',
                              'without_ground.world')


def lens(d):
    k1, k2, p1, p2, k3 = d
    return """
        <distortion><k1>%r</k1><k2>%r</k2><k3>%r</k3><p1>%r</p1><p2>%r</p2>
          <center>0.5 0.5</center></distortion>""" % (k1, k2, k3, p1, p2)


AUTO = """
        <autoDistortion>true</autoDistortion>
        <borderCrop>false</borderCrop>"""
SENSORS = [
    camera_sensor('pinhole', width=SQUARE, height=SQUARE, fov=SQUARE_FOV),
    camera_sensor('barrel', width=SQUARE, height=SQUARE, fov=SQUARE_FOV, lens=lens(BARREL),
                  extra=AUTO),
    camera_sensor('pincushion', width=SQUARE, height=SQUARE, fov=SQUARE_FOV,
                  lens=lens(PINCUSHION), extra=AUTO),
    camera_sensor('calibrated', width=WIDE, height=HIGH, fov=WIDE_FOV, lens=lens(CALIBRATED),
                  extra=AUTO),
]


def wall_sdf(columns=12, rows=12):
    """Tiles in a plane facing the cameras, its left edge at y = WALL_LEFT_Y, centred on the
    lenses' height, alternately red and blue."""
    visuals = []
    for i in range(columns):
        for j in range(rows):
            y = WALL_LEFT_Y - TILE * (i + 0.5)
            z = LENS_Z + TILE * (j - rows / 2 + 0.5)
            visuals.append("""<visual name="tile_%d_%d"><pose>%r %r %r 0 0 0</pose>
<geometry><box><size>0.02 %r %r</size></box></geometry>
<material><script><uri>file://media/materials/scripts/gazebo.material</uri><name>%s</name>
</script></material></visual>""" % (i, j, WALL_X + 0.01, y, z, TILE, TILE,
                                    'Gazebo/Red' if (i + j) % 2 else 'Gazebo/Blue'))
    return """<sdf version="1.6"><model name="wall"><static>true</static><link name="link">
%s</link></model></sdf>""" % '\n'.join(visuals)


def record(ros, rospy, engine, names, world=()):
    """The first image and CameraInfo of each of the cameras `names` (the others, unwatched,
    render nothing), in the world file `world` (by default Gazebo's empty world)."""
    from sensor_msgs.msg import CameraInfo, Image
    _, api = start(ros, rospy, engine, SENSORS, scene=wall_sdf(), world=world)
    topics = {'/%s/image_raw' % name: Image for name in names}
    topics.update({'/%s/camera_info' % name: CameraInfo for name in names})
    heard = hear_periods(ros, rospy, api, topics, 1, 100)
    return ({name: image_array(heard['/%s/image_raw' % name][0]) for name in names},
            {name: heard['/%s/camera_info' % name][0] for name in names})


def image_array(image):
    assert image.encoding == 'rgb8'
    return numpy.frombuffer(image.data, dtype=numpy.uint8).reshape(
        image.height, image.width, 3).astype(float)


def distort(x, y, d):
    """The Brown-Conrady model on normalised coordinates, D ordered as CameraInfo's."""
    k1, k2, p1, p2, k3 = d
    r2 = x * x + y * y
    radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
    return (x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
            y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y)


def undistort_image(image, k, d):
    """OpenCV's undistort(image, K, D) of one channel: each pixel of the result takes the image's
    value (interpolated bilinearly; 0 outside it) where the model sends its pinhole point."""
    height, width = image.shape
    fx, cx, fy, cy = k[0], k[2], k[4], k[5]
    v, u = numpy.indices((height, width), dtype=float)
    xd, yd = distort((u - cx) / fx, (v - cy) / fy, d)
    su, sv = fx * xd + cx, fy * yd + cy
    inside = (su >= 0) & (sv >= 0) & (su <= width - 1) & (sv <= height - 1)
    u0 = numpy.clip(numpy.floor(su), 0, width - 2).astype(int)
    v0 = numpy.clip(numpy.floor(sv), 0, height - 2).astype(int)
    a, b = su - u0, sv - v0
    top = image[v0, u0] * (1 - a) + image[v0, u0 + 1] * a
    bottom = image[v0 + 1, u0] * (1 - a) + image[v0 + 1, u0 + 1] * a
    out = top * (1 - b) + bottom * b
    out[~inside] = 0
    return out


def undistort_points(u, v, k, d, iterations=50):
    """OpenCV's undistortPoints (its fixed-point iteration), back in pixels."""
    fx, cx, fy, cy = k[0], k[2], k[4], k[5]
    xd, yd = (u - cx) / fx, (v - cy) / fy
    x, y = xd.copy(), yd.copy()
    k1, k2, p1, p2, k3 = d
    for _ in range(iterations):
        r2 = x * x + y * y
        radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
        x = (xd - (2 * p1 * x * y + p2 * (r2 + 2 * x * x))) / radial
        y = (yd - (p1 * (r2 + 2 * y * y) + 2 * p2 * x * y)) / radial
    return fx * x + cx, fy * y + cy


def left_edge(image, row):
    """Where the wall's left edge crosses `row`, to a fraction of a pixel: the green channel is
    the background's grey left of it and 0 on both tile colours, so the grey share summed across
    the edge is how far into the window the grey reaches (pixel c spanning c - 0.5 to c + 0.5)."""
    green = image[row, :, 1]
    first = int(numpy.argmax(green < GREY / 2))
    assert first > 6 and numpy.all(green[:first - 6] == GREY), row
    start, stop = first - 6, first + 6
    assert numpy.all(green[stop - 2:stop] == 0), row
    return start - 0.5 + (green[start:stop] / GREY).sum()


@pytest.mark.parametrize('engine', ENGINES)
def test_undistorting_with_camera_info_gives_the_pinhole_image_back(ros, rospy_client, engine):
    images, infos = record(ros, rospy_client, engine, ('pinhole', 'barrel', 'pincushion'))
    # The red channel tells the red tiles (102) from the blue (0).
    pinhole = images['pinhole'][:, :, 0]
    border = 50  # as Gazebo's test
    crop = (slice(border, SQUARE - border), slice(border, SQUARE - border))
    for name, d in (('barrel', BARREL), ('pincushion', PINCUSHION)):
        info = infos[name]
        assert list(info.D) == pytest.approx(list(d), abs=1e-15), name
        assert list(info.K) == pytest.approx(list(infos['pinhole'].K), rel=1e-15), name
        distorted = images[name][:, :, 0]
        assert not numpy.array_equal(distorted, pinhole), name  # the lens does something

        def difference(coefficients):
            fixed = undistort_image(distorted, info.K, coefficients)
            return numpy.abs(fixed[crop] - pinhole[crop]).sum()

        least = difference(list(info.D))
        # Left alone the lens's image differs far more: the tiles' edges have moved.
        assert least < difference([0.0] * 5) / 4, name
        for i in range(5):
            for step in (0.01, -0.01):
                moved = list(info.D)
                moved[i] += step
                assert difference(moved) >= least, (name, i, step)


@pytest.mark.parametrize('engine', ENGINES)
def test_a_straight_edge_bends_as_the_lens_says_and_camera_info_straightens_it(
        ros, rospy_client, engine):
    images, infos = record(ros, rospy_client, engine, ('calibrated',), world=[WITHOUT_GROUND])
    image, info = images['calibrated'], infos['calibrated']
    assert list(info.D) == pytest.approx(list(CALIBRATED), abs=1e-15)
    f = WIDE / (2 * math.tan(WIDE_FOV / 2))
    assert info.K[0] == pytest.approx(f, rel=1e-12)
    rows = numpy.arange(5, HIGH - 5)
    measured = numpy.array([left_edge(image, row) for row in rows])

    # Where the model puts the edge: the wall's edge is the pinhole image's column
    # cx - f y / Z (cx = (W - 1) / 2, pixel centres), a vertical line; each of its points goes
    # where the lens sends it.
    centre_u, centre_v = (WIDE - 1) / 2, (HIGH - 1) / 2
    x = -WALL_LEFT_Y / WALL_X
    y = numpy.linspace(-1, 1, 20001)
    xd, yd = distort(numpy.full_like(y, x), y, CALIBRATED)
    expected = numpy.interp(rows, centre_v + f * yd, centre_u + f * xd)
    assert numpy.all(numpy.abs(measured - expected) <= 1.0), numpy.abs(measured - expected).max()
    assert measured.max() - measured.min() > 10  # it bends, by ten pixels and more

    # CameraInfo's K and D straighten it: its undistorted points on one line, within a pixel,
    # where the pinhole camera sees the edge, within a pixel and a half (Gazebo's K puts the
    # principal point at (W + 1) / 2, a pixel right of the image's middle, and the edge is found
    # to half a pixel).
    u, v = undistort_points(measured, rows.astype(float), info.K, info.D)
    slope, intercept = numpy.polyfit(v, u, 1)
    assert numpy.abs(u - (slope * v + intercept)).max() <= 1.0
    assert abs(slope) < 0.005
    assert numpy.abs(u - (centre_u + f * x)).max() <= 1.5
