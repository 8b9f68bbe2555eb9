"""5-axis finishing of meshes by seed 000's 3D C-space method (section 3.5.5): CC paths by drive planes with
their local frames (cc_paths), the posture grid and the tool's touching placement (posture), the lift that
clears every triangle (lift), the top bound from the tolerance (top_bound) and the C-space (cspace)."""
