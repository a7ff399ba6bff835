"""Safety: barrier certificates on a look-ahead point (one small exact QP per robot) filter every command of a
robot with a body; the figures a run reports."""
