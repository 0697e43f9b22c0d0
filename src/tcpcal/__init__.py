"""tcpcal: TCP and TOOL-frame calibration solvers for industrial robots.

Unit-agnostic (lengths come out in the unit they went in; the CLI speaks mm and degrees),
numpy/scipy only, no UI and no robot model. The methods and their equations are described in
``docs/methods.md``; the public interfaces in the API reference (``docs/reference/tcpcal.md``).

Typical use::

    import tcpcal
    result = tcpcal.solve_xyz4(rotations, positions_mm)   # R_world_flange (N,3,3), p (N,3)
    result.tcp, result.rms_error, result.ci95_radius
"""

from tcpcal.beam import BeamAxisResult, BeamResult, solve_beam, solve_beam_axis
from tcpcal.errors import DegenerateTouchesError, InvalidInputError, TcpcalError
from tcpcal.formats import FORMATS, export_tool, import_tool
from tcpcal.library import (
    ToolLibrary,
    ToolLibraryError,
    ToolLibraryWarning,
    default_library_path,
)
from tcpcal.orientation import (
    OrientationResult,
    solve_abc_world,
    solve_three_point,
    solve_three_point_lstsq,
)
from tcpcal.origin import TcpResult, solve_reference, solve_xyz4
from tcpcal.pose_quality import (
    CandidateGain,
    PoseQuality,
    assess_touches,
    candidate_gain,
)
from tcpcal.tcp_zx import TcpZxResult, solve_tcp_zx
from tcpcal.tool import Calibration, Tool, abc_deg_from_rotation, rotation_from_abc_deg

__version__ = "0.1.0"

__all__ = [
    "BeamAxisResult",
    "BeamResult",
    "FORMATS",
    "Calibration",
    "CandidateGain",
    "DegenerateTouchesError",
    "InvalidInputError",
    "OrientationResult",
    "PoseQuality",
    "TcpResult",
    "TcpZxResult",
    "TcpcalError",
    "Tool",
    "ToolLibrary",
    "ToolLibraryError",
    "ToolLibraryWarning",
    "abc_deg_from_rotation",
    "assess_touches",
    "candidate_gain",
    "default_library_path",
    "export_tool",
    "import_tool",
    "rotation_from_abc_deg",
    "solve_abc_world",
    "solve_beam",
    "solve_beam_axis",
    "solve_reference",
    "solve_tcp_zx",
    "solve_three_point",
    "solve_three_point_lstsq",
    "solve_xyz4",
]
