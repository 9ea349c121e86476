"""The parts of the closed-form IK (:mod:`anthroarm.ik.closed_form`, its public entry points),
one concern a module:

- :mod:`.kinds` — the kinds of closed form (planar 2R, SRS 7R, the IK-Geo classes and
  searches), one interface and one registry;
- :mod:`.results` — what a call returns;
- :mod:`.poses` — the inputs, checked;
- :mod:`.finish` — from a kind's branches to a result: FK check, polish, rescue, reasons;
- :mod:`.limits` — the rescue of solutions on the joint limits and the polish;
- :mod:`.trees` — the arm of a tree and frames other than the tool;
- :mod:`.book` — the book's own procedure for the prosthetic arm (Table 7.2).
"""
