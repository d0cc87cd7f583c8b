"""A new plan library under a running plan tree: what carries over, what restarts.

Called by the engine at the tick the team adopts a library (:mod:`alica.engine.reload`).
The tree is walked from the root; names decide what is the same:

* a plan that still exists replaces the node's plan in place. The agent keeps its
  entry point and state, and the node keeps its teammates and successes. Its
  allocation is done again only when what allocation reads changed (entry points,
  utility, pre- or run-time condition);
* an entry point that is gone leaves the agent idle in the plan, and the plan is
  allocated again;
* a state that is gone sends the agent to the initial state of its entry point
  (a ``reload`` trace note says so);
* a plan whose synchronisations changed starts their handshakes again;
* in the state the agent stays in, a child whose reference (name, bindings) and
  element are unchanged keeps running: a behaviour keeps its skill, a plan its
  node (carried over in turn), a planning problem its runtime and generated plan.
  A changed child restarts, a removed one stops, an added one starts;
* the world model is not touched.
"""

from __future__ import annotations

from collections.abc import Callable

from alica.engine.node import PlanNode
from alica.engine.slot import Slot
from alica.engine.team import key_text
from alica.engine.tree import PlanTree
from alica.model import Behaviour, Plan, PlanLibrary, PlanType
from alica.model.digest import LibraryChanges

Emit = Callable[..., None]


def _allocation_changed(old: Plan, new: Plan) -> bool:
    """Whether what allocation reads of a plan changed."""
    return (
        old.entry_points != new.entry_points or old.utility != new.utility or old.pre != new.pre or old.run != new.run
    )


class CarryOver:
    """Carries one agent's plan tree over to a new library (see the module docstring).

    Args:
        tree: the agent's plan tree (it reads plans from the new library afterwards).
        changes: what the new library adds, removes and changes.
        now: the time of the switch.
        emit: the engine's trace (``reload`` notes).
    """

    def __init__(self, tree: PlanTree, changes: LibraryChanges, now: float, emit: Emit) -> None:
        self.tree = tree
        self.changes = changes
        self.now = now
        self.emit = emit
        self.restarted: list[str] = []
        """Keys of the children started again (changed or added), for the trace."""

    def apply(self, library: PlanLibrary, root: PlanNode | None) -> None:
        """Use ``library`` in the tree and carry ``root`` and everything below it over."""
        self.tree.use(library)
        if root is not None:
            self.node(root)

    def node(self, node: PlanNode) -> None:
        """Carry one plan node over (the plan of the new library, its state, its children)."""
        old = node.plan
        new = self.tree.plan(old.name)
        node.plan = new
        if _allocation_changed(old, new):
            node.invalidate()
        if old.synchronisations != new.synchronisations:
            node.parts.syncs.drop(node.key)  # their handshakes start again, with the new settings
        entry_points = {ep.name for ep in new.entry_points}
        for agent, (ep, _state) in list(node.believed.items()):
            if ep is not None and ep not in entry_points:
                del node.believed[agent]  # a teammate in an entry point that is gone: its next claim says where it is
                node.invalidate()
        if node.ep is not None and node.ep not in entry_points:
            self.emit("reload", key=node.key_text, note=f"entry point '{node.ep}' was removed: allocated again")
            node.set_entry(None, self.now)
            node.invalidate()
            return
        if node.state is None or node.ep is None:
            return
        if node.state not in {s.name for s in new.states}:
            target = new.entry_point(node.ep).state
            assert target is not None  # validated plans have an initial state per entry point
            self.emit(
                "reload",
                key=node.key_text,
                note=f"state '{node.state}' was removed: back to '{target}', the initial state of '{node.ep}'",
            )
            node.enter_state(target, self.now)
            return
        self.children(node)

    def children(self, node: PlanNode) -> None:
        """Keep the unchanged children of the node's state, restart the changed ones, start the added ones."""
        assert node.state is not None
        refs = node.plan.state(node.state).children
        old = {slot.ref.name: slot for slot in node.slots}
        slots: list[Slot] = []
        for ref in refs:
            slot = old.pop(ref.name, None)
            if slot is not None and slot.ref == ref and self._same_element(slot):
                slot.element = self.tree.library.abstract(ref.name)
                slot.ref = ref
                slots.append(slot)
                if slot.node is not None:
                    self.node(slot.node)
                continue
            if slot is not None:
                slot.stop()
            started = node.start_child(ref, self.now)
            slots.append(started)
            self.restarted.append(key_text(started.key))
        for slot in old.values():
            slot.stop()
        node.slots = slots
        self.tree.changed()

    def _same_element(self, slot: Slot) -> bool:
        """Whether the child's element still exists and runs as before."""
        name = slot.ref.name
        changes = self.changes
        if name in changes.names("behaviour") or name in changes.names("plantype") or name in changes.names("problem"):
            return False  # a behaviour's skill or parameters, a plan type's alternatives, a problem changed
        try:
            element = self.tree.library.abstract(name)
        except KeyError:
            return False
        if isinstance(slot.element, Behaviour) or isinstance(slot.element, PlanType):
            return type(element) is type(slot.element)
        if isinstance(slot.element, Plan):
            return isinstance(element, Plan)  # a changed plan is carried over, not restarted
        return slot.runtime is not None and type(element) is type(slot.element)
