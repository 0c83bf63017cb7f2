"""Fixture dimensions that are not in the configuration, for the Python layout rules: the
same figures as `rascal_workcell::Workcell` (include/rascal_workcell/Workcell.hpp), where their
sources are given; a test reads the header and fails when they differ."""

SCALE_HOUSING_MARGIN = 0.015  # [m] housing beyond the weighing platform (kScaleHousingMargin)
