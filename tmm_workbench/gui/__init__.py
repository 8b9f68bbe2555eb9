"""TMM's GUI layer: the workbench, commands, task panels, view providers (may import everything)."""
