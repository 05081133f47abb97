"""How a run ended: the compiled solver's status codes and their one-line explanations."""

from __future__ import annotations

__all__ = ["STATUS_OK", "STATUS_STEP_TOO_SMALL", "STATUS_EVENT_LIMIT", "STATUS_TABLE_LIMIT", "STATUS_COLLAPSED",
           "STATUS_MESSAGES"]

STATUS_OK = 0
STATUS_STEP_TOO_SMALL = 1  # also the outcome of a non-finite state: such steps are rejected and shrunk
STATUS_EVENT_LIMIT = 2     # more contact events inside one record step than EVENTS_PER_WINDOW allows
STATUS_TABLE_LIMIT = 3     # the impact or trace table would exceed its row cap
STATUS_COLLAPSED = 4       # a storey's drift ratio exceeded stop_drift_ratio: the run ended there (not an error)
#: One-line explanation of every status, for error messages (``{t}``: the time the run stopped, s).
STATUS_MESSAGES = {
    STATUS_OK: "completed",
    STATUS_STEP_TOO_SMALL: ("the solver's step size fell below round-off at t = {t:.6g} s; "
                            "loosen solver.rtol/atol or check the model for unrealistic stiffness"),
    STATUS_EVENT_LIMIT: ("more than the allowed number of contact events within one record step at t = {t:.6g} s "
                         "(an impact sequence that does not end, e.g. chattering contacts); run stopped"),
    STATUS_TABLE_LIMIT: ("the impact or contact-trace table reached its row cap at t = {t:.6g} s "
                         "(too many impacts or closed-contact samples); run stopped"),
    STATUS_COLLAPSED: "collapsed: a storey's drift ratio exceeded solver.stop_drift_ratio at t = {t:.6g} s",
}
