"""Batched shape-function derivatives over all families (no per-family
Python loop).  One module per construction."""
from .taylor import wte1_gradients, mte1_gradients
from .least_squares import mls1_master_values, mls1_values
from .quadratic import wte2_gradients

#: shape-function derivative builders by name (thesis Table 5.1)
GRADIENTS = {
    "WTE1": wte1_gradients,
    "MTE1": mte1_gradients,
    "WTE2": wte2_gradients,
}

__all__ = ["wte1_gradients", "mte1_gradients", "wte2_gradients",
           "mls1_master_values",
           "mls1_values",
           "GRADIENTS"]
