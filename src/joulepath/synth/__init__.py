"""Synthetic data: grow a small real energy table with SDV, then check it.

* :class:`Synthesizer` / :func:`synthesize`: SDV's GaussianCopula, CTGAN, CopulaGAN
  and TVAE behind one adapter (thesis §3.4, §4.2); saved models are pickles,
  guarded by a SHA-256 sidecar;
* :func:`quality_report`: SDMetrics' column shapes, column pair trends, overall;
* :func:`describe`, :func:`plot_distributions`, :func:`compare`: statistics and
  distribution overlays of several tables (thesis Figs 4.3-4.10);
* :func:`utility`: train on a table, test on held-out real moves;
* :func:`kinematic_consistency`, :func:`repair_kinematics`: do the TCP columns
  agree with FK(q)?

SDV and SDMetrics are optional (``pip install 'joulepath[synth]'``); only
``joulepath.synth._sdv`` imports them, when first needed.
"""

from joulepath.synth._compare import (
    FEATURE_GROUPS,
    SCORES_FILE,
    STATISTICS,
    STATISTICS_FILE,
    Comparison,
    compare,
    describe,
    histogram_mode,
    plot_distributions,
)
from joulepath.synth._kinematics import (
    TCP_TOLERANCE_M,
    euler_zyx_rates,
    kinematic_consistency,
    repair_kinematics,
    tcp_error,
)
from joulepath.synth._quality import quality_report
from joulepath.synth._sdv import METHODS
from joulepath.synth._synthesize import (
    NotFittedError,
    SynthConfig,
    Synthesizer,
    UntrustedModelFile,
    model_columns,
    sidecar_path,
    synthesize,
)
from joulepath.synth._utility import UtilityScore, utility

__all__ = [
    "Comparison",
    "FEATURE_GROUPS",
    "METHODS",
    "NotFittedError",
    "SCORES_FILE",
    "STATISTICS",
    "STATISTICS_FILE",
    "SynthConfig",
    "Synthesizer",
    "TCP_TOLERANCE_M",
    "UntrustedModelFile",
    "UtilityScore",
    "compare",
    "describe",
    "euler_zyx_rates",
    "histogram_mode",
    "kinematic_consistency",
    "model_columns",
    "plot_distributions",
    "quality_report",
    "repair_kinematics",
    "sidecar_path",
    "synthesize",
    "tcp_error",
    "utility",
]
