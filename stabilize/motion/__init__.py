"""The visual motion of a clip (pass 1): rotations from optical flow, their support, the
rows they were seen on, and the repair of frames that too few vectors agreed on."""

from stabilize.motion.files import read_rotations, write_rotations
from stabilize.motion.repair import repair_unreliable
from stabilize.motion.track import VisualTrack

__all__ = ["VisualTrack", "read_rotations", "repair_unreliable", "write_rotations"]
