# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""pointform: multiresolution modeling from point samples.

Points -> oriented surfels -> signed field -> marching cubes -> semi-regular multiresolution
mesh, over numpy arrays. The work is done by the C++ library (the extension module
``pointform._pointform``); arrays of returned objects are read-only views of its storage, and
every heavy call releases the GIL.
"""

from ._pointform import *  # noqa: F401,F403
from ._pointform import __doc__ as _module_doc  # noqa: F401
from ._pointform import __version__  # noqa: F401
