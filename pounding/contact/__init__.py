"""Contact laws of the gap elements and the catalogue of ξ formulas.

``xi``    the ξ formulas p(e) = ξ v0 / kh, a registry keyed by name
``laws``  the contact laws (hertz-damp, kelvin, ...), a registry keyed by ``law``
"""
