"""Sound at a rigid wall (``pcabench study --walls``): accuracy, stability and cost at a wall; measured.json
holds the one measurement not in the store, with its command."""
