"""
The pure core: Python + numpy only; imports nothing above it (no ROS, no bags, no tools).

* ``geometry``: vectors, rotations, poses, rigid-body velocity, capsule distance (one copy);
* ``bat``: the bat's radius profile, knob and tip from a pose;
* ``toi``: exact time of impact (``scalar`` and ``batch`` siblings over shared ``capsule``
  polynomials and ``polynomials`` root finding; ``seed``, the derivation's method);
* ``motion``: how each body moves between two samples, one path class per model;
* ``detector``: the stream detector, a facade over its parts (``gate``, ``streams``,
  ``pairing``, ``scheduler``, ``broadphase``, ``sweep``, ``episodes``, ``kinematics``,
  ``predictor`` with ``bat_judgment`` and ``bat_window``; typed ``events``; the one
  parameter table in ``config``);
* ``prediction``: ball and bat forecasts and the search for their first contact.
"""
