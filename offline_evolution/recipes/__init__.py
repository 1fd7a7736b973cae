"""Recipes: how each shipped controller was trained, as a file run by one command.

``config/recipes/*.yaml`` (:mod:`.spec`) lists a controller's steps, the budgets
(:mod:`.budget`) scale them for a quick check, and :mod:`.runner` runs them in-process and
compares the outputs with the shipped files (:mod:`.digest`); docs/design.md, "Recipes".
"""
