"""Planning above the strategies: choices made by running a strategy for candidates and measuring what each
leaves (optimal_cutter)."""
