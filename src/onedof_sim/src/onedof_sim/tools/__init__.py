"""Command-line tools beside the simulator node: plot (rqt_plot's syntax) and spawn_cli
(spawn_model's arguments and model sources)."""
