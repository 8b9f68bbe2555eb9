"""Stock simulation: the z-map the kernel cuts (grid, stock), what a tool path leaves
(simulate), compared with the design (compare), and how long it takes (cycle_time)."""
