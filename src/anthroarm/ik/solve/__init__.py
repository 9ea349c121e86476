"""One-shot inverse kinematics: ``aa.ik.solve(robot, T)`` -> :class:`~anthroarm.ik.result.IKResult`.

Method: damped Gauss–Newton (Levenberg–Marquardt) on the pose error with projected steps
(:mod:`.lm`), seeds from the closed form or from a table of the arm's own poses
(:mod:`.seeds`), restarts inside the joint limits under a time budget, and for redundant arms a
secondary objective in the null space of the task (:mod:`.nullspace`).  Per iteration (frame
``frame``, m and rad)::

    e = log₆(T(θ)⁻¹ T*)  (body twist (v; ω)),   J = ᵇJ(θ)  (LOCAL frame Jacobian, 6 × nv),
    Δθ = Jᵀ (J Jᵀ + λ I)⁻¹ e,   λ = λ₀ + k ‖e‖²,   θ ← clip(θ + Δθ, θ_min, θ_max)

(the book's feedback-compensation step, Ch. 7 §7-5, damped toward the steepest descent of §7-6
(A9), with the joint ranges of (7-84)–(7-85) enforced exactly by an active set).  An attempt
stops when the error no longer falls by 10 % in three iterations; the next seed is then tried.
Success is decided on the exact errors ‖p* − p‖ and the angle of Rᵀ R* from Pinocchio's FK.

Any robot ``aa.load`` takes: the solver reads ``robot.chain``.  It iterates on θ, the
independent joints' positions in Pinocchio's v order; a continuous joint's angle is unbounded
and enters Pinocchio as (cos θ, sin θ) (:meth:`anthroarm.chain.Chain.configuration`), so steps
integrate on the circle and the returned angle is the one reached from the seed.  Mimic joints
are carried by Pinocchio's Jacobian columns; joints off the frame's path have zero columns and
keep the caller's ``q0`` (else their reference posture).  An OpenSim model with nonlinear
couplings (``robot.coupling``) is solved in its independent coordinates, the same kernel on the
Jacobian J·dφ/dq (:mod:`.coupled`).

Seeds, in order (:mod:`.seeds`):

1. the closed-form solutions of :func:`anthroarm.ik.analytic` (nearest the posture first), when
   ``analytic=True``, or with ``analytic="auto"`` and no ``q0`` where the closed form is cheap
   (:func:`.seeds.closed_form_cheap`); they are exact, so one evaluation verifies them (on a
   closed 6R class without a posture or swivel objective the FK of the closed form's own
   compiled call, which also gives the reported errors: the answer in one call);
2. ``q0`` when given (clipped into the limits);
3. the seed table, nearest the target first (aligned on the first and last joints where they
   turn fully), then the next :data:`.seeds.TABLE_SEEDS` − 1 nearest entries;
4. uniform random configurations inside the limits, until ``max_time`` or ``max_restarts``;
   with ``analytic="auto"`` the closed form joins after :data:`.api.ANALYTIC_AFTER` failed
   attempts where it was not first.

Targets (:mod:`.targets`): a 4×4 rigid pose, a position (3,) (e = p* − p with the
LOCAL_WORLD_ALIGNED linear rows of J) or a rotation (3, 3) (e = log₃(Rᵀ R*), LOCAL angular rows).
A leading batch axis solves N targets (:class:`~anthroarm.ik.result.IKBatchResult`), in lockstep
where the table seeds them (:func:`.api.solve_lockstep`).

Redundant arms (human arm): ``posture`` adds ½‖θ − θ_ref‖² in the null space (a secant step
along a one-dimensional self-motion; :func:`.nullspace.posture`); ``swivel=φ*`` places the
elbow at the swivel angle φ* (:func:`.nullspace.swivel`).

Speed (:mod:`.lm`): each attempt is one call of a compiled kernel (:mod:`anthroarm.jit`: its
one source runs in the interpreter until the compiled code is ready), the frame's FK and
Jacobian from the chain's one compiled forward kinematics
(:func:`anthroarm.ik.fk.chain_fk_jacobian`, read from ``robot.chain``).

Layout of one call (:mod:`.api`), one job per function: :func:`.targets.parse` (the targets;
one 4×4 array straight to the rigid check) and :func:`.targets.check_options`; the one-time
tables and kernels, before any clock starts (``max_time`` never counts them); per target
:func:`.api.solve_one` — :class:`.api.SeedOrder` gives the seeds in turn,
:func:`.lm.attempt` refines each, the null-space phase follows a success — or, for a batch,
:func:`.api.solve_lockstep` (the rounds of :class:`.api.Lockstep`: evaluate, restart, step);
:meth:`~anthroarm.ik.result.IKBatchResult.collect` gathers the answers.

Threads and memory (:mod:`.workspace`): one Robot may be used from several threads at once
(per-thread ``pin.Data`` and kernel arrays); the per-robot cache holds the Robot weakly and
nothing that refers to it.
"""

from .api import solve

__all__ = ["solve"]
