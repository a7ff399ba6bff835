"""The world beyond the paper's open square: what a map and polygons make of the grid, the wedge's pass over
the grid with what walls and teammates hide (eq. 3, 6, 9), line of sight, a disk's clearance, free paths
and the paper's global law among walls."""
