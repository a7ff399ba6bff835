"""Robots with mass and wheels (issue 37): a MuJoCo world behind the unicycle's commands.

:mod:`model.physics.base` has the base's parameters and its wheels' kinematics, :mod:`model.physics.scene` the
world written as MJCF (floor, walls, robots), :mod:`model.physics.world` the world stepped once per control
period with every robot's command in, and the contacts it counts.
"""
