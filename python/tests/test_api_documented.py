"""Every public name of the package is documented and typed: a docstring on
each function, class and method, and an annotation on every parameter and
return value of the Python layer (the extension's are in ``_cdyn.pyi``)."""

import inspect

import cdyn


def public_callables():
    for name in cdyn.__all__:
        obj = getattr(cdyn, name)
        yield name, obj
        if inspect.isclass(obj) and obj.__module__ == "cdyn":
            for attr, member in vars(obj).items():
                if not attr.startswith("_") and (inspect.isfunction(member) or isinstance(member, property)):
                    yield f"{name}.{attr}", member


def test_every_public_name_has_a_docstring():
    missing = [name for name, obj in public_callables() if not (inspect.getdoc(obj) or "").strip()]
    assert missing == []


def test_every_python_function_is_annotated():
    unannotated = []
    for name, obj in public_callables():
        func = obj.fget if isinstance(obj, property) else obj
        if not inspect.isfunction(func) or func.__module__ != "cdyn":
            continue
        sig = inspect.signature(func)
        params = [p for p in sig.parameters.values() if p.name != "self" and p.annotation is inspect.Parameter.empty]
        if params or sig.return_annotation is inspect.Signature.empty:
            unannotated.append(name)
    assert unannotated == []


def test_the_stub_lists_every_function_of_the_extension():
    stub = (cdyn.__path__[0] + "/_cdyn.pyi")
    text = open(stub).read()
    for name in dir(cdyn._cdyn):
        if not name.startswith("_") and callable(getattr(cdyn._cdyn, name)):
            assert f"def {name}(" in text or f"class {name}(" in text or f"class {name}:" in text, name
