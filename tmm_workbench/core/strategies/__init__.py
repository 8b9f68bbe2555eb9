"""Strategies: one module each (the contract is in docs/design.md, "Adding a strategy").

Each module holds a params dataclass (core.params.StrategyParams: defaults, units and ranges written once),
SUPPORTED_TOOLS (the Cutter kinds it takes), estimate_work (refuses what the machine cannot do before
allocating), and compute(model, tool, params, progress) -> core.segments.StrategyResult (cut segments and
diagnostics); core.linking links the segments of every strategy into a tool path."""
