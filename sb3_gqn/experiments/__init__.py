"""The comparison suite: the runner (local processes or a Ray cluster), its agents and suites, the report, the
figures, the statistics behind the intervals, and the reference run (the repository's main job)."""
