"""The notebook's tests use the product's fixtures and constants (the solver binary, the shared ci runs,
tests/python/conftest.py): the notebook may import the product, never the reverse. Loaded under a name of its own
so that this file stays the `conftest` the notebook's tests import from."""
import importlib.util
import pathlib

_PRODUCT = pathlib.Path(__file__).resolve().parents[2] / "tests" / "python" / "conftest.py"
_spec = importlib.util.spec_from_file_location("product_conftest", _PRODUCT)
_product = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_product)
globals().update({k: v for k, v in vars(_product).items() if not k.startswith("__")})
