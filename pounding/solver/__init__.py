"""The compiled event-driven integrator (Dormand–Prince 5(4) with located contact events).

``integrator``  :class:`~pounding.solver.integrator.System`, :func:`~pounding.solver.integrator.integrate`
``jit``         numba start-up shortcuts
"""
