"""One robot of the team: the agent process and the ``Robot`` drivers (simulated unicycle)."""
