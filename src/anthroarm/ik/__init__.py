"""Inverse kinematics.

* closed-form IK of every arm whose geometry allows it, every branch (:func:`analytic`, Ch. 7 §7-2;
  IK-Geo's subproblems, :mod:`anthroarm.ik.closed_form`);
* the book's spatial cell method and iterative methods (Ch. 7 §7-3 … §7-6);
* QP differential IK (:mod:`anthroarm.ik.qp`) and the one-shot solver :func:`solve`.
"""

from . import qp
from .closed_form import (
    AnalyticBatchResult,
    AnalyticIKResult,
    ClosedForm,
    analytic,
    analytic_batch,
    closed_form_info,
    has_analytic,
)
from .qp.tasks.swivel import swivel_angle
from .result import IKBatchResult, IKResult
from .solve import solve
