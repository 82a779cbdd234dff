"""Shared helpers of the study tests."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd
from swarm_experiments.study import VOLATILE_COLUMNS


def _plain(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return [_plain(item) for item in value.tolist()]
    if hasattr(value, 'item') and not isinstance(value, (list, dict)):
        value = value.item()
    if isinstance(value, float) and math.isnan(value):
        return None
    if isinstance(value, list):
        return [_plain(item) for item in value]
    return value


def comparable(frame: pd.DataFrame) -> list[dict[str, Any]]:
    """Rows without the timing/host columns, sorted by run id, as plain Python values."""
    kept = frame.drop(columns=[c for c in VOLATILE_COLUMNS if c in frame.columns])
    kept = kept.sort_values('run_id').reset_index(drop=True)
    kept = kept[sorted(kept.columns)]
    return [{k: _plain(v) for k, v in row.items()} for row in kept.to_dict('records')]
