"""The 3-axis Surface op's pipeline below its strategy (core.strategies.raster_drop), one module per stage:
pattern (where the tool goes in XY) -> positioning (the points dropped and refined) -> forward_step (segments in
cutting order, the lean fit) -> verification (variable_step; cusp_check's report) -> linking (core.linking); and
what the stages share: the parameters (params), the pass segments (segments) and the cusp measurement's cells and
dense raster (measure)."""
