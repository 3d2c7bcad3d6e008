"""The benchmarks' harness is the demos' (``demos/harness.py``, one copy):
this module loads that file under the name ``harness``, so that
``python benchmarks/NAME.py`` finds it without editing ``sys.path``."""
import importlib.util
import os
import sys

_PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir,
                     "demos", "harness.py")
_spec = importlib.util.spec_from_file_location("harness", _PATH)
_module = importlib.util.module_from_spec(_spec)
sys.modules[__name__] = _module  # `from harness import x` reads the demos'
_spec.loader.exec_module(_module)
