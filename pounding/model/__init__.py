"""Building models: YAML text → validated data → buildings, gap elements and matrices.

``document``  YAML text → plain data with the line of every value (hardened YAML 1.2 reader)
``schema``    the nested pydantic models: one validation pass, one-line located errors
``model``     :class:`~pounding.model.model.Model`, buildings, gap elements, ``load_model``
``plan``          plan buildings: 3-DOF floors, planes, K, M and K_G by virtual work (pure functions)
``plan_contacts`` contacts from the plan: facing edges, gap, contact points, penetration and slip weights
``ground_pair``   two-component ground motion: record pairs, angle of incidence, components on a time grid
``plan_schema``   the schema of plan models (buildings with ``plan:``)
``plan_model``    :class:`~pounding.model.plan_model.PlanModel`, ``load_plan_model`` (not yet integrated)
"""
