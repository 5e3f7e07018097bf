"""Camera capture and image processing, installed as ``petriflow.vision``.

The SMART scenario's IP camera and image-processing agent (seed 003, §2.4), over a
pybullet world's overhead camera:

* :mod:`~petriflow.vision.capture`: frames from a world camera (640 x 480 default,
  any size on request) and the ``vision.capture`` action (renders only when fired);
* :mod:`~petriflow.vision.segment`: RGB → HSV, per-colour HSV thresholds, labels
  (0 floor, 1 black, 2..5 red, blue, yellow, green), the 8-neighbourhood mode filter,
  contours, the obstacle mask and the grey label map with robots as squares of side L;
* :mod:`~petriflow.vision.pose`: a robot's pose from its black and white discs, and
  the exact pixel ↔ world homography of the marker plane;
* :mod:`~petriflow.vision.pipeline`: :func:`~petriflow.vision.pipeline.process`
  (frame → :class:`~petriflow.vision.pipeline.Scene`) and the ``vision.locate`` action;
* :mod:`~petriflow.vision.markers`: marker robots and marker hats built from pybullet
  primitives, the white floor, and a ready test arena.

Conventions: the floor is white (:func:`~petriflow.vision.markers.white_floor`
recolours pybullet's checker plane); each robot's colour patch encloses a black and a
white disc; looking along the robot's heading, black is on the left and white on the
right, i.e. heading = direction black → white turned +90° (counter-clockwise from
above), in radians counter-clockwise from +x. Pixels are ``(column, row)`` array
indices; world positions are metres on the plane of the discs' tops.
"""
