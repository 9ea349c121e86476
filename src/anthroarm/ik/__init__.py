"""Inverse kinematics.

* closed-form IK of the book's arms, every branch (:func:`analytic`, Ch. 7 §7-2);
* the book's spatial cell method and iterative methods (Ch. 7 §7-3 … §7-6);
* QP differential IK (:mod:`anthroarm.ik.qp`) and the one-shot solver :func:`solve`.
"""

from . import qp
from .result import IKBatchResult, IKResult
from .solve import solve
from .closed_form import AnalyticBatchResult, AnalyticIKResult, analytic, analytic_batch, has_analytic
from .qp.tasks.swivel import swivel_angle
