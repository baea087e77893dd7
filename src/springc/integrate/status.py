"""How a compiled run ended: the status codes the kernels return (plain Python, no numba).

The kernels never raise; they stop and return one of these codes with the time and the
state where it happened, so that the caller can word its own error message.
"""

from enum import IntEnum


class Status(IntEnum):
    """The outcome of a run of :func:`springc.integrate.dop853` or ``fixed_step``."""

    SUCCESS = 0
    #: the step size fell below 10 ulp of t (DOP853): failure time/state = last accepted
    STEP_TOO_SMALL = 1
    #: the right-hand side returned NaN or inf: time/state = that evaluation's arguments
    NON_FINITE_DERIVATIVE = 2
    #: a state became NaN or inf (fixed-step methods): time/state = the output time reached
    NON_FINITE_STATE = 3
    #: ``max_steps`` steps were taken before the end: time/state = last accepted step
    MAX_STEPS = 4
    #: the model set its failure flag ``z[-1]`` (springc's generated modules do so when a
    #: Newton iteration fails): time/state = that evaluation's arguments; ``z`` keeps the flag
    MODEL_FAILED = 5
    #: a zero-crossing function changed sign against its held sign: time = the located
    #: crossing (the right end of a bracket narrower than about 1e-12 relative), state =
    #: the left limit there; ``fired`` says which crossing(s), rows before it are filled
    STATE_EVENT = 6
    #: the run reached the requested stop time ``t_stop`` exactly (a step ends on it):
    #: time/state = that time and the state there; rows before it are filled
    TIME_EVENT = 7


#: the counters a compiled run keeps (indices into its ``counts`` array): accepted
#: steps, rejected steps, right-hand-side evaluations, Jacobian evaluations
ACCEPTED, REJECTED, RHS_CALLS, JACOBIAN_CALLS = 0, 1, 2, 3
COUNTERS = 4
