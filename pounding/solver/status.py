"""How a run ended: the compiled solver's status codes and their one-line explanations."""

from __future__ import annotations

__all__ = ["STATUS_OK", "STATUS_STEP_TOO_SMALL", "STATUS_EVENT_LIMIT", "STATUS_TABLE_LIMIT", "STATUS_COLLAPSED",
           "STATUS_UNSTABLE", "STATUS_ENERGY_INCONSISTENT", "STATUS_NAMES", "STATUS_MESSAGES", "COLLAPSE_CAUSES"]

STATUS_OK = 0
STATUS_STEP_TOO_SMALL = 1  # also the outcome of a non-finite state: such steps are rejected and shrunk
STATUS_EVENT_LIMIT = 2     # more contact events inside one record step than EVENTS_PER_WINDOW allows
STATUS_TABLE_LIMIT = 3     # the impact or trace table would exceed its row cap
STATUS_COLLAPSED = 4       # a building collapsed (a storey past its collapse drift ratio, or an IMK storey at zero
#                            strength): the run ended there (not an error)
STATUS_UNSTABLE = 5        # a storey's resistance (restoring force + P-Delta) fell to zero as its drift grew: ended there
STATUS_ENERGY_INCONSISTENT = 6  # set after the run: the contacts dissipated more energy than the run received
#: Why a building collapsed (the archive's ``collapse_cause``): its storey passed its collapse drift
#: ratio, an IMK storey reached its ultimate drift (zero strength), or a storey lost its lateral
#: resistance to P-Delta (status ``unstable``); "" when nothing collapsed.
COLLAPSE_CAUSES = ("drift_ratio", "zero_strength", "unstable")
#: The archive's ``status`` attribute of a run that ended with each code (the others raise their message).
STATUS_NAMES = {
    STATUS_OK: "completed",
    STATUS_COLLAPSED: "collapsed",
    STATUS_UNSTABLE: "unstable",
    STATUS_ENERGY_INCONSISTENT: "energy_inconsistent",
}
#: One-line explanation of every status, for error messages (``{t}``: the time the run stopped, s).
STATUS_MESSAGES = {
    STATUS_OK: "completed",
    STATUS_STEP_TOO_SMALL: ("the solver's step size fell below round-off at t = {t:.6g} s; "
                            "loosen solver.rtol/atol or check the model for unrealistic stiffness"),
    STATUS_EVENT_LIMIT: ("more than the allowed number of contact events within one record step at t = {t:.6g} s "
                         "(an impact sequence that does not end, e.g. chattering contacts); run stopped"),
    STATUS_TABLE_LIMIT: ("the impact or contact-trace table reached its row cap at t = {t:.6g} s "
                         "(too many impacts or closed-contact samples); run stopped"),
    STATUS_COLLAPSED: "collapsed: building {building} collapsed at t = {t:.6g} s, storey {storey} {cause}; the run "
                      "ended there",
    STATUS_UNSTABLE: ("unstable: storey {storey} lost its lateral resistance at t = {t:.6g} s (restoring force plus "
                      "P-Delta fell to zero as its drift grew: a sidesway collapse); the run ended there"),
    STATUS_ENERGY_INCONSISTENT: ("energy_inconsistent: the contacts dissipated {dissipated:.4g} J, more than the "
                                 "{available:.4g} J the run received (input work, initial energy, gravity under "
                                 "P-Delta); the contact events were not resolved: tighten solver.atol (and "
                                 "atol_velocity), e.g. by 100, and keep solver.tolerance_scaling on"),
}
