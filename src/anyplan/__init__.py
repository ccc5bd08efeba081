"""anyplan: Sequential BIT* and friends for a mobile robot among static and moving obstacles."""

import logging

__version__ = "0.1.0"

logging.getLogger(__name__).addHandler(logging.NullHandler())

__all__ = ["__version__"]
