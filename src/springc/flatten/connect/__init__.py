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
    ConnectionGraph,
    Edge,
    check_branches,
    graph_node,
    graph_value,
    misplaced,
    operator_nodes,
    uses_graph,
)
from .connections import ConnectionSets

__all__ = [
    "CARDINALITY",
    "GRAPH_EQUATIONS",
    "GRAPH_FUNCTIONS",
    "ConnectionGraph",
    "ConnectionSets",
    "Edge",
    "apply_cardinalities",
    "cardinality_call",
    "check_branches",
    "check_connector_size",
    "check_no_connect",
    "graph_node",
    "graph_value",
    "misplaced",
    "operator_nodes",
    "uses_graph",
]
