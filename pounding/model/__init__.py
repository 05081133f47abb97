"""Building models: YAML text → validated data → buildings, gap elements and matrices.

``document``  YAML text → plain data with the line of every value (hardened YAML 1.2 reader)
``schema``    the nested pydantic models: one validation pass, one-line located errors
``model``     :class:`~pounding.model.model.Model`, buildings, gap elements, ``load_model``
"""
