"""The coordinator process: membership, steps, snapshots, rebuild; its planning is model.planning."""
