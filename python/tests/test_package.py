"""The package as an editor sees it: documented, its stubs matching the native module."""

import ast
import doctest
import inspect
import pathlib

import cdyn
from cdyn import _cdyn


def test_the_module_docstring_example_runs():
    failed, tried = doctest.testmod(cdyn)
    assert tried > 0 and failed == 0


def test_stubs_name_exactly_what_the_native_module_has():
    stub = pathlib.Path(_cdyn.__file__).with_name("_cdyn.pyi")
    tree = ast.parse(stub.read_text())
    stubbed = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    stubbed |= {n.target.id for n in tree.body if isinstance(n, ast.AnnAssign)}
    native = {n for n in dir(_cdyn) if not n.startswith("_")} | {"__version__"}
    assert stubbed == native
    assert (stub.parent / "py.typed").exists()


def test_every_public_name_is_documented():
    for name in cdyn.__all__:
        assert getattr(cdyn, name).__doc__, name


def test_every_method_and_property_of_the_results_is_documented():
    for cls in (cdyn.Result, cdyn.Sweep, cdyn.Scenario):
        for name, attr in vars(cls).items():
            if not name.startswith("_") and (callable(attr) or isinstance(attr, property) or hasattr(attr, "__get__")):
                # inspect.getdoc, as help() and editors: it finds a slot's doc in __slots__.
                assert inspect.getdoc(getattr(cls, name)), f"{cls.__name__}.{name}"
