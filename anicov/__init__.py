"""anicov: multi-robot anisotropic vision-based coverage control (Franco et al.)."""

__version__ = "0.1.0"
