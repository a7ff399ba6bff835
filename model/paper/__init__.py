"""The paper, pure (Franco et al.): the unicycle (eq. 1), the wedge sensor (eq. 2, 4), the fixed-point coverage
map and e_D (eq. 3–5), the laws (eq. 7–16), Algorithm 1 (objectives) and 2 (assignment), the metrics
(eq. 18–19, Fig. 7). It reads only the scenario."""
