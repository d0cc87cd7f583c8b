"""Task allocation: which agent takes which entry point of which plan.

The exact, deterministic task allocation of ALICA (IMPERA Section 6.3,
Definitions 6.2-6.3). Every agent that has the same view of the team computes
the same assignment, which is how a team agrees without negotiating.

Semantics, for a candidate plan ``p`` and the agents ``A`` (sorted by id):

* Effective cardinality of entry point ``e``: ``min' = max(0, e.min - s)``,
  ``max' = max(0, e.max - s)`` with ``s = successes[p][e]``, the agents that
  already succeeded there. A complete assignment is valid iff every agent takes
  one entry point of ``p`` or idles (only if ``allow_idle``) and every entry
  point's count lies in ``[min', max']``. Candidates with
  ``sum(min') > len(A)`` are skipped.
* ``N = max(1, min(p.max_cardinality, len(A)))`` (ALICA's normalisation).
* Priority term ``pri = sum over assigned agents a of Pref(role(a), task(e(a))) / N``;
  an assigned agent with ``Pref < 0`` vetoes the assignment (utility -1).
* Summand terms ``f_i = sum over assigned agents of summand(p, s_i, a, e(a)) / N``;
  a value ``<= -1`` vetoes.
* Similarity, only when ``old`` is given, ``old.plan == p.name`` and the
  similarity weight is positive: with ``O`` the agents in both the problem and
  ``old``, ``sim = |{a in O: e(a) == old.entry_of(a)}| / |O|`` (0 if ``O`` is
  empty); idling again counts as kept. Otherwise ``sim = 0``.
* ``U = (w0 pri + sum w_i f_i + ws sim) / (w0 + sum w_i + ws)``, dividing only
  if the weight sum is positive. The weight sum always includes ``ws``.
* U is computed exactly (rational arithmetic on the given numbers) and
  compared as ``round(U * 10**9)``. The optimum is the valid, non-vetoed
  assignment with the largest key over all candidates; ties go to the earlier
  plan, then to the lexicographically smallest vector of entry point indices
  over the agents sorted by id (idle = ``len(p.entry_points)``, the last choice).

Every term is a sum of per-agent contributions, so U is additive over agents;
:func:`allocate` exploits this with an exact A* search, :func:`exhaustive`
enumerates. Both return the same assignment on every input.
"""

from alica.allocation.assignment import AllocationResult, Assignment
from alica.allocation.problem import AllocationError, AllocationProblem, SummandFn
from alica.allocation.reference import exhaustive
from alica.allocation.roles import AgentSpec, RoleError, assign_roles
from alica.allocation.search import allocate
from alica.allocation.utility import utility

__all__ = [
    "AgentSpec",
    "AllocationError",
    "AllocationProblem",
    "AllocationResult",
    "Assignment",
    "RoleError",
    "SummandFn",
    "allocate",
    "assign_roles",
    "exhaustive",
    "utility",
]
