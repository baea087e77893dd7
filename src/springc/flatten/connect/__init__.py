"""Connections: connection sets to equations (``connections``), their rules
(``connect_rules``), the overdetermined-graph operators (``connection_graph``) and
``cardinality``."""

from __future__ import annotations

from .cardinality import NAME as CARDINALITY
from .cardinality import apply_cardinalities, cardinality_call
from .connect_rules import check_connector_size, check_no_connect
from .connection_graph import (
    GRAPH_EQUATIONS,
    GRAPH_FUNCTIONS,
    check_branches,
    graph_equation,
    misplaced,
)
from .connections import ConnectionSets

__all__ = [
    "CARDINALITY",
    "GRAPH_EQUATIONS",
    "GRAPH_FUNCTIONS",
    "ConnectionSets",
    "apply_cardinalities",
    "cardinality_call",
    "check_branches",
    "check_connector_size",
    "check_no_connect",
    "graph_equation",
    "misplaced",
]
