"""The 3-axis Surface op's pipeline below its strategy (core.strategies.raster_drop): the shared parameters
(params), the pass segments (segments), the cusp measurement's cells and dense raster (measure), the
verification stage (variable_step) and the check of what a cusp mode left (cusp_check)."""
