"""The temporal study's sequences (reference_scenes/sequence_*): 24 frames each at 320x180,
one thing changing in each, so that what temporal accumulation reaches, and what it breaks,
can be told apart:

- `rest`: a workshop floor seen by a camera that does not move: every frame is the same
  picture, so accumulated AO can only converge (how far, how fast);
- `pan`: packed shelves passed by a camera that trucks sideways and closes in while it turns
  to keep them in view: history must be reprojected, and the shelves' edges uncover the
  wall behind them;
- `traffic`: a static camera on a wall and a floor, with a crate and a pillar against the
  wall, while a box slides across the floor in front of them, a bracket turns on the spot and
  a drum rolls towards the camera: the floor and wall they uncover are disoccluded (no history
  there), and the moving objects' own shading moves with them.

Every motion is keyed at the first and the last frame with linear interpolation, so the
motion per frame is constant and the Vector pass is exact. Geometry is built with kit.Builder
(flat-shaded, grey) and the workshop and shelves with the clutter family's builders at seeds
of their own. Metres, z up.
"""

from families import clutter, kit

FIRST, LAST = 1, 24  # every sequence's manifest "frames"
WIDTH, HEIGHT = 320, 180  # its "resolution"


def keyframes(obj, keys):
    """Keys ``obj`` at each frame of ``keys`` ({frame: (location, euler xyz in radians)}),
    interpolated linearly."""
    obj.rotation_mode = 'XYZ'
    for frame, (location, rotation) in sorted(keys.items()):
        obj.location = location
        obj.rotation_euler = rotation
        obj.keyframe_insert("location", frame=frame)
        obj.keyframe_insert("rotation_euler", frame=frame)
    for curve in obj.animation_data.action.fcurves:
        for key in curve.keyframe_points:
            key.interpolation = 'LINEAR'


def camera_keys(path):
    """{frame: (location, target)} -> keyframes' {frame: (location, euler)}: a look-at
    rotation per key, each Euler compatible with the previous one (no angle wraps between
    keys)."""
    out, previous = {}, None
    for frame, (location, target) in sorted(path.items()):
        quat = (kit.Vector(target) - kit.Vector(location)).to_track_quat('-Z', 'Y')
        euler = quat.to_euler('XYZ', previous) if previous is not None else quat.to_euler('XYZ')
        previous = euler
        out[frame] = (location, tuple(euler))
    return out


def finish(path, lens, radius, clip_start=0.05):
    """The camera on ``path`` ({frame: (location, target)}; one key: at rest), the
    protocol's settings, the sequence's size and frame range."""
    import bpy
    start = path[min(path)]
    kit.finish(start[0], start[1], lens, radius, clip_start=clip_start)
    scene = bpy.context.scene
    if len(path) > 1:
        keyframes(scene.camera, camera_keys(path))
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.frame_start, scene.frame_end, scene.frame_step = FIRST, LAST, 1
    scene.frame_set(FIRST)


def rest():
    mat = kit.grey()
    b = kit.Builder()
    clutter.workshop(b, kit.rng(61), mat)
    b.build("Workshop", mat)
    finish({FIRST: ((3.2, -4.8, 1.6), (0.2, 0.6, 0.35))}, 24.0, 0.3)


def pan():
    mat = kit.grey()
    b = kit.Builder()
    clutter.shelf(b, kit.rng(62), mat)
    b.build("Shelves", mat)
    # The shelves move 2-3 px a frame on screen (fx = 249 px at 28 mm on 320 px).
    finish({FIRST: ((-0.7, -2.0, 1.25), (-0.25, 0.3, 0.95)),
            LAST: ((0.5, -1.6, 1.35), (0.3, 0.3, 1.0))}, 28.0, 0.1, clip_start=0.02)


def traffic():
    mat = kit.grey()
    room = kit.Builder()
    room.box((-6.0, -6.0, -0.1), (6.0, 1.0, 0.0))                  # the floor
    room.box((-6.0, 1.0, 0.0), (6.0, 1.2, 2.8))                    # the wall (face y = 1)
    room.box((-1.6, 0.45, 0.0), (-0.9, 1.0, 0.6))                  # a crate against it
    room.box((0.8, 0.55, 0.0), (1.15, 0.9, 2.8))                   # a square pillar
    room.box((-6.0, 0.94, 0.0), (6.0, 1.0, 0.12))                  # a skirting board
    room.build("Room", mat)
    # A box sliding right along the floor, past the crate and the pillar (about 10 px a frame).
    box = kit.Builder()
    box.box((-0.3, -0.25, 0.0), (0.3, 0.25, 0.5))
    keyframes(box.build("Slider", mat), {FIRST: ((-2.2, 0.1, 0.0), (0.0, 0.0, 0.0)),
                                         LAST: ((1.5, 0.1, 0.0), (0.0, 0.0, 0.0))})
    # An L-shaped bracket turning a quarter turn on the spot, near the camera.
    bracket = kit.Builder()
    bracket.box((-0.35, -0.05, 0.0), (0.35, 0.05, 0.3))
    bracket.box((-0.35, -0.05, 0.0), (-0.25, 0.4, 0.3))
    keyframes(bracket.build("Bracket", mat), {FIRST: ((-1.0, -1.3, 0.0), (0.0, 0.0, 0.0)),
                                              LAST: ((-1.0, -1.3, 0.0), (0.0, 0.0, 1.5708))})
    # A drum on its side rolling towards the camera (its axis along x; one turn is 2 pi r).
    drum = kit.Builder()
    drum.cylinder((-0.25, 0.0, 0.0), (0.25, 0.0, 0.0), 0.25, 16)
    keyframes(drum.build("Drum", mat), {FIRST: ((0.9, -0.3, 0.25), (0.0, 0.0, 0.0)),
                                        LAST: ((0.9, -1.7, 0.25), (5.6, 0.0, 0.0))})
    finish({FIRST: ((-0.1, -3.3, 1.3), (-0.2, 0.6, 0.35))}, 24.0, 0.5)


VARIANTS = {"rest": rest, "pan": pan, "traffic": traffic}


def build(variant):
    VARIANTS[variant]()
