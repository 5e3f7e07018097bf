"""Analysis of nets as free functions (reachability, boundedness, soundness, invariants)."""
