"""The intermediate representations exchanged between stages.

Import the modules, not names: ``from springc.ir import expr, flat, dae, ode, syntax``.
Order inside: ``syntax`` and ``expr`` first, then ``flat``, ``dae``, ``ode``.
"""
