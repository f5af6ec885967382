#!/usr/bin/env python3
"""Writes examples/camera_user's generated inputs: the 5 cameras' calibrations (calibration/),
the user's keyframes (user.keys) and the rigid scene (scene.json, the paper's scene plus a
ledge and the box the user pushes off it). Run once from this folder; the outputs are checked in.
"""
import json
import math

# The rig: 5 cameras on a 3.2 m circle around the user's volume, at the heights of
# vrflow::camera::cameraRing (low ones see under the arms, high ones over them), 320x240.
WIDTH, HEIGHT, FOCAL = 320, 240, 230.0
TARGET = (0.25, 0.95, -0.55)
HEIGHTS = (1.4, 3.4, 0.5, 3.0, 0.8)
RADIUS = 3.2


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def normalize(a):
    n = math.sqrt(sum(x * x for x in a))
    return tuple(x / n for x in a)


def matrix(rows, cols, data):
    values = ", ".join(repr(float(v)) for v in data)
    return f"!!opencv-matrix\n   rows: {rows}\n   cols: {cols}\n   dt: d\n   data: [ {values} ]\n"


def calibration(eye):
    # vrflow::camera::lookAtCamera: OpenCV axes, z forward, x right, y down.
    z = normalize(sub(TARGET, eye))
    x = normalize(cross(z, (0.0, 1.0, 0.0)))
    y = cross(z, x)
    rotation = x + y + z
    translation = tuple(-sum(r * e for r, e in zip(row, eye)) for row in (x, y, z))
    k = (FOCAL, 0, (WIDTH - 1) / 2, 0, FOCAL, (HEIGHT - 1) / 2, 0, 0, 1)
    return ("%YAML:1.0\n---\n"
            f"image_width: {WIDTH}\nimage_height: {HEIGHT}\n"
            f"camera_matrix: {matrix(3, 3, k)}"
            f"distortion_coefficients: {matrix(1, 5, (0, 0, 0, 0, 0))}"
            f"rotation_matrix: {matrix(3, 3, rotation)}"
            f"translation_vector: {matrix(3, 1, translation)}"
            "avg_reprojection_error: 0.\n")


for n in range(5):
    angle = 2 * math.pi * n / 5
    eye = (TARGET[0] + RADIUS * math.sin(angle), HEIGHTS[n],
           TARGET[2] + RADIUS * math.cos(angle))
    with open(f"calibration/cam{n}.yml", "w") as out:
        out.write(calibration(eye))

# The user: vrflow::camera::standingPose (facing +z, the right arm reaching forward, the left
# held out to the side) turned to face +x (towards the pool), then moved as a whole.
STANDING = {
    "head": (0.000, 1.620, 0.000), "neck": (0.000, 1.450, 0.000),
    "pelvis": (0.000, 0.950, 0.000), "shoulder_l": (0.200, 1.420, 0.000),
    "elbow_l": (0.450, 1.380, 0.050), "wrist_l": (0.620, 1.300, 0.200),
    "hand_l": (0.660, 1.280, 0.300), "shoulder_r": (-0.200, 1.420, 0.000),
    "elbow_r": (-0.300, 1.450, 0.250), "wrist_r": (-0.320, 1.500, 0.480),
    "hand_r": (-0.330, 1.520, 0.580),
}
# (time s, body x, drop y, body z): the right hand starts at (0.23, 1.52, 0.33).
KEYS = (
    (0.0, -0.35, 0.0, 0.0),
    (0.2, -0.35, 0.0, 0.0),
    (1.0, -0.05, 0.0, 0.0),    # walks 0.3 m: the right hand pushes the box off the ledge
    (1.2, -0.05, 0.0, 0.0),
    (1.8, -0.08, -0.80, -0.28),  # crouches: the right hand and forearm go through the net
    (2.0, -0.08, -0.80, -0.28),
    (2.8, -0.08, -0.80, -0.78),  # sweeps the arm 0.5 m through the net and the water
    (3.0, -0.08, -0.80, -0.78),
)
with open("user.keys", "w") as out:
    out.write("# examples/camera_user's user (written by make_scene.py): the standing pose facing +x,\n"
              "# moved as a whole. TIME JOINT X Y Z\n")
    for time, bx, dy, bz in KEYS:
        for joint, (x, y, z) in STANDING.items():
            out.write(f"{time:.1f} {joint} {z + bx:.3f} {y + dy:.3f} {-x + bz:.3f}\n")

with open("../paper_scene/scene.json") as f:
    scene = json.load(f)
scene["comment"] = ("examples/camera_user (written by make_scene.py): the paper's scene "
                    "(examples/paper_scene/scene.json) plus a kinematic ledge in front of the "
                    "user's right hand and the box it pushes off.")
scene["bodies"].append({"name": "ledge", "shape": {"type": "box", "halfExtents": [0.16, 0.05, 0.15]},
                        "kinematic": True, "position": [0.46, 1.35, 0.33]})
scene["bodies"].append({"name": "pushed-box", "shape": {"type": "box", "halfExtents": [0.1, 0.1, 0.1]},
                        "density": 500, "position": [0.38, 1.5, 0.33]})
with open("scene.json", "w") as out:
    json.dump(scene, out, indent=1)
    out.write("\n")
