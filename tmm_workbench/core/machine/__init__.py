"""Machine models: kinematics from (tool tip, tool axis) to machine joints and back, joint limits and
motion time. `tarus.TarusMachine` (the seed's 5-axis Tarus head-head mill), `tarus.ThreeAxisMachine`."""
from tmm_workbench.core.machine.tarus import (JOINT_NAMES, JointLimitError, Joints, JointSpeeds, TarusMachine,
                                              ThreeAxisMachine, unit_axis)

__all__ = ["JOINT_NAMES", "JointLimitError", "Joints", "JointSpeeds", "TarusMachine", "ThreeAxisMachine",
           "unit_axis"]
