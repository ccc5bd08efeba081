"""anyplan's YAML writer and reader agree: what ``dump_yaml`` writes, ``load_yaml`` reads back."""

from __future__ import annotations

import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.world.yaml_load import dump_yaml, load_yaml

_SCALARS = (st.text(max_size=12) | st.floats(allow_nan=False, width=64) | st.integers(-10**12, 10**12)
            | st.booleans() | st.none()
            | st.from_regex(r"\A[-+]?[0-9][0-9_]{0,3}(\.[0-9]{0,3})?[eE][-+]?[0-9]{1,3}\Z"))
_DOCS = st.recursive(_SCALARS, lambda inner: st.lists(inner, max_size=4)
                     | st.dictionaries(st.text(min_size=1, max_size=8), inner, max_size=4),
                     max_leaves=20)


def test_exponent_text_stays_text():
    # The loader reads 1e5 (no dot) as a number, as YAML 1.2 and JSON do; plain YAML 1.1 writes
    # the text "1e5" unquoted, which would come back as a float.
    doc = {"name": "1e5", "description": "0E0", "value": 1e5}
    assert load_yaml(yaml.safe_dump(doc))["name"] == 1e5  # the mismatch dump_yaml removes
    assert load_yaml(dump_yaml(doc)) == doc


@settings(max_examples=200, deadline=None, database=None)
@given(_DOCS)
def test_dump_then_load_gives_the_document_back(doc):
    back = load_yaml(dump_yaml(doc, sort_keys=False, allow_unicode=True))
    assert back == doc
    assert type(back) is type(doc)
