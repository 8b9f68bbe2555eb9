"""Pictures of tool paths for reports and the main job (matplotlib, imported inside the functions)."""
