"""The package says today what it said when the baseline was recorded, on every bundled bag."""

import json

from support.baseline import analyze_documents, BASELINE
from support.documents import differences


def test_every_bundled_bag_and_model_unchanged() -> None:
    """Impacts, near misses, predictions, drops, gaps: stamps to the ns, floats to ULPs."""
    expected = json.loads(BASELINE.read_text())
    actual = json.loads(json.dumps(analyze_documents()))
    found = differences(actual, expected)
    assert found == [], '\n'.join(found[:20])
    assert sum(len(document['impacts']) for document in expected.values()) > 50
