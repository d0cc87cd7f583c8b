"""pRoPhEt MAS: planning problems filled in at run time.

Planning domains and problems, planners behind one interface and the
planning-problem runtime arrive with their issue; the plan format already
carries planning problems and skill signatures (:mod:`alica.model.planning`).
"""
