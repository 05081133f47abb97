"""Models: YAML text → validated data → the one description of a structure (docs/architecture.md).

``document``  YAML text → plain data with the line of every value (hardened YAML 1.2 reader)
``schema``    the model file's front-end: nested pydantic models, one validation pass, one-line located errors
``plan_schema``   the front-end of the plan syntax (buildings with ``plan:``, storeys with planes, faces)
``floors``    floors with one or three degrees of freedom and the planes between them: weights, K, M, K_G
``building``  :class:`~pounding.model.building.Building` (floors, storeys, planes, damping) and ``Damping``
``outline``   contacts between outlines in plan: facing edges, gap, contact points, penetration and slip weights
``ground``    the ground motion: one component, or two with an angle; record pairs; components on a time grid
``model``     :class:`~pounding.model.model.Model`, the contact points, faces and links, ``load_model``
``scales``    the time scales of a model and the work a run will take
"""
