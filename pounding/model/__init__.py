"""Building models: YAML text → validated data → buildings, gap elements and matrices.

``schema``  YAML document with its line map, validation with one-line errors
``model``   :class:`~pounding.model.model.Model`, buildings, gap elements, ``load_model``
"""
