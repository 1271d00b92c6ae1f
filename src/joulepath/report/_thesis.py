"""What the 2025 thesis reports in its results chapter (Chapter 4), as plain data.

A generated report prints these items beside our own results. Each item records one table or
figure of Chapter 4: its caption, section, the stage of our pipeline that reproduces it, a short
statement of what the thesis reports in it, and the key numbers exactly as the thesis text prints
them (``shared/seed/000_c43d5ab320f1a219.txt``, a text conversion of the PDF). ``line`` is the
1-based line of the caption in that text, so every number can be traced back.

Nothing here is computed or estimated: a value that the text does not print legibly is left out.
Where the thesis contradicts itself (a table and the paragraph about it), ``shows`` says so.
"""

from __future__ import annotations

from dataclasses import dataclass

from joulepath.errors import InvalidInput

__all__ = [
    "HYPOTHESES",
    "STAGES",
    "THESIS_ITEMS",
    "Hypothesis",
    "ThesisItem",
    "items_for_stage",
    "thesis_item",
]

#: Pipeline stages an item can belong to, in pipeline order.
STAGES: tuple[str, ...] = ("data", "synth", "importance", "train", "optimize", "bench")


@dataclass(frozen=True, slots=True)
class ThesisItem:
    """One table or figure of the thesis' results chapter.

    Attributes
    ----------
    key : str
        ``"Table 4.1"`` … ``"Table 4.7"`` or ``"Figure 4.1"`` … ``"Figure 4.19"``.
    caption : str
        The thesis caption as plain text (LaTeX and markdown removed, legends shortened).
    section : str
        Thesis section holding the item, e.g. ``"4.3.2"``.
    stage : str
        One of :data:`STAGES`: the stage of our pipeline that reproduces the item.
    shows : str
        What the thesis reports in the item, in its own terms (1–3 sentences).
    numbers : tuple of (label, value)
        Key numbers, each value exactly as the thesis prints it; ``()`` when the text has none.
    line : int
        1-based line number of the caption in the seed text.
    """

    key: str
    caption: str
    section: str
    stage: str
    shows: str
    numbers: tuple[tuple[str, str], ...]
    line: int

    def __post_init__(self) -> None:
        if self.stage not in STAGES:
            raise InvalidInput(f"{self.key}: stage {self.stage!r} is not one of {', '.join(STAGES)}")


@dataclass(frozen=True, slots=True)
class Hypothesis:
    """One of the thesis' research hypotheses (§1.1.4), verbatim.

    Attributes
    ----------
    key : str
        ``"H1"``, ``"H2"`` or ``"H3"``.
    text : str
        The hypothesis as the thesis words it (its grammar included).
    line : int
        1-based line number of the hypothesis in the seed text.
    """

    key: str
    text: str
    line: int


HYPOTHESES: tuple[Hypothesis, ...] = (
    Hypothesis(
        "H1",
        "The ML-based, data-driven, models achieve higher performance and are faster in determining "
        "the energy use of a six-axis IRM compared to classic mathematical models.",
        150,
    ),
    Hypothesis(
        "H2",
        "Synthetic data can be generated models which can have scores as high as the models trained "
        "on real-world data.",
        151,
    ),
    Hypothesis(
        "H3",
        "The application of an optimization algorithm based on a memetic principle can optimize paths "
        "better than the algorithms based just on the evolutionary principles.",
        152,
    ),
)

_GRID_CAPTION = "The results of best models found using grid search and cross validation procedures, for "

THESIS_ITEMS: tuple[ThesisItem, ...] = (
    # ---- 4.1 Data analysis results: feature importance -------------------------------------
    ThesisItem(
        key="Figure 4.1",
        caption="The influence of individual features on the energy of each joint.",
        section="4.1",
        stage="importance",
        shows=(
            "Stacked feature-importance scores, computed on the real-world dataset, for the energy of "
            "joints 1 to 4. Each joint's own position and speed influence its energy most, and the "
            "tool-space position (x, y, z) matters more for the first three joints."
        ),
        numbers=(),
        line=1623,
    ),
    ThesisItem(
        key="Figure 4.2",
        caption="The influence of individual features on the energy of each joint (cont.).",
        section="4.1",
        stage="importance",
        shows=(
            "The same for joints 5 and 6 and for the energy of the entire manipulator. Orientation "
            "variables matter more for the last three joints, and the speeds of the first two joints "
            "have the highest influence on the total energy, so the MA's targeted search works on the "
            "path parameters of joints 1 and 2."
        ),
        numbers=(),
        line=1639,
    ),
    # ---- 4.2 Data synthetization results -----------------------------------------------------
    ThesisItem(
        key="Figure 4.3",
        caption="Numerical evaluation of synthetization methods.",
        section="4.2.1",
        stage="synth",
        shows=(
            "Column shape (a) and column pair (b) scores of the datasets generated by Copulas, CTGAN, "
            "CopulaGAN and TVAE against the real dataset. TVAE has the best column shape score and "
            "Copulas the best column pair score; TVAE is judged best overall (the text gives no column "
            "shape score for CopulaGAN)."
        ),
        numbers=(
            ("column shape: Copulas", "0.82"),
            ("column shape: CTGAN", "0.80"),
            ("column shape: TVAE", "0.93"),
            ("column pair: Copulas", "0.99"),
            ("column pair: TVAE", "0.98"),
            ("column pair: CopulaGAN", "0.96"),
            ("column pair: CTGAN", "0.95"),
        ),
        line=1663,
    ),
    ThesisItem(
        key="Figure 4.4",
        caption="The distribution of measured joint angle positions in the dataset.",
        section="4.2.2",
        stage="synth",
        shows=(
            "Histograms of the joint positions, real data against samples of the four synthesizers. "
            "CTGAN piles values at the ends of the range, CopulaGAN tends towards a uniform and Copulas "
            "towards a normal distribution; only TVAE follows the more complex shapes closely."
        ),
        numbers=(),
        line=1697,
    ),
    ThesisItem(
        key="Figure 4.5",
        caption="The distribution of measured joint angle speeds in the dataset.",
        section="4.2.2",
        stage="synth",
        shows=(
            "Joint speeds, real against synthetic. TVAE is the only method that reproduces the dip of "
            "speed values near zero, while Copulas approximates a normal distribution."
        ),
        numbers=(),
        line=1709,
    ),
    ThesisItem(
        key="Figure 4.6",
        caption="The distribution of measured joint angle accelerations in the dataset.",
        section="4.2.2",
        stage="synth",
        shows=(
            "Joint accelerations, which the real data concentrates around zero. Copulas again "
            "approximates a standard normal distribution centred at zero; the other methods fit "
            "noticeably better."
        ),
        numbers=(),
        line=1739,
    ),
    ThesisItem(
        key="Figure 4.7",
        caption="The distribution of TCP positions, speeds and accelerations in the dataset.",
        section="4.2.2",
        stage="synth",
        shows=(
            "TCP position, speed and acceleration in tool space. CTGAN generates too many values near "
            "the extremes of the variable ranges, a flaw the thesis takes as grounds to drop it."
        ),
        numbers=(),
        line=1777,
    ),
    ThesisItem(
        key="Figure 4.8",
        caption="The distribution of TCP orientations, speeds and accelerations in the dataset.",
        section="4.2.2",
        stage="synth",
        shows=(
            "TCP orientation angles and their derivatives. CopulaGAN and CTGAN generate many values at "
            "the range extremes, Copulas produces normal-looking data for centrally concentrated "
            "variables, and TVAE performs decently with minor errors."
        ),
        numbers=(),
        line=1817,
    ),
    ThesisItem(
        key="Figure 4.9",
        caption="The distribution of measured joint angle accelerations in the dataset.",
        section="4.2.2",
        stage="synth",
        shows=(
            "Per the text, the energy distributions (the caption repeats that of Figure 4.6). The sixth "
            "joint's energy has extra peaks near the extremes of its range that no method recreates; "
            "the thesis concludes that TVAE is the best method overall."
        ),
        numbers=(),
        line=1825,
    ),
    ThesisItem(
        key="Figure 4.10",
        caption=(
            "The difference between the descriptive statistics of the real-world and synthetic datasets "
            "in comparison to the real-world dataset."
        ),
        section="4.2.3",
        stage="synth",
        shows=(
            "Mean, mode, range, standard deviation, skewness and kurtosis of each variable in the real, "
            "simulated and synthetic (TVAE) datasets. Synthetic data stays close to the real data, while "
            "simulated data differs most in central tendency (notably the joint energies and E), so the "
            "simulation appears shifted from reality."
        ),
        numbers=(),
        line=1843,
    ),
    # ---- 4.3.1 Hyperparameter selection (grid search, five-fold CV) --------------------------
    ThesisItem(
        key="Table 4.1",
        caption=_GRID_CAPTION + "MLP.",
        section="4.3.1",
        stage="train",
        shows=(
            "Best MLP per target (E1 to E6, E) and dataset (real, synth, sim) from grid search with "
            "five-fold cross-validation. Mean R² is 0.999 everywhere except simulated E (0.993, with the "
            "adam solver); all best models use the identity activation."
        ),
        numbers=(
            ("real E: mean R²", "0.999"),
            ("real E: mean MAE", "2.2·10⁻²"),
            ("real E1: mean MAE", "1.6·10⁻²"),
            ("synth E: mean MAE", "2.1·10⁻²"),
            ("synth E1: mean MAE", "1.7·10⁻²"),
            ("sim E: mean R²", "0.993"),
            ("sim E: mean MAE", "4.348"),
            ("sim E: σ MAE", "0.316"),
            ("lowest mean MAE (sim E5)", "0.001"),
        ),
        line=1875,
    ),
    ThesisItem(
        key="Table 4.2",
        caption=_GRID_CAPTION + "PAR.",
        section="4.3.1",
        stage="train",
        shows=(
            "Best passive aggressive regressors: mean R² 0.999 and mean MAE 0.037 to 0.049 for most "
            "targets, higher than the MLP's. The outlier for E (mean R² 0.991, MAE 4.91) sits in the "
            "table's simulated block, although the text attributes it to the synthetic dataset."
        ),
        numbers=(
            ("real E: mean R²", "0.999"),
            ("real E: mean MAE", "4.4·10⁻²"),
            ("synth E: mean MAE", "4.9·10⁻²"),
            ("sim E: mean R²", "0.991"),
            ("sim E: mean MAE", "4.91"),
            ("sim E: σ MAE", "0.234"),
            ("best (synth E2): mean MAE", "0.037"),
        ),
        line=1908,
    ),
    ThesisItem(
        key="Table 4.3",
        caption=_GRID_CAPTION + "SVR.",
        section="4.3.1",
        stage="train",
        shows=(
            "Best support vector regressors: mean R² 0.999 and mean MAE 0.036 to 0.044 for most "
            "targets, with an outlier for simulated E. The best model is synthetic E1."
        ),
        numbers=(
            ("real E: mean R²", "0.999"),
            ("real E: mean MAE", "4.0·10⁻²"),
            ("synth E: mean MAE", "4.0·10⁻²"),
            ("sim E: mean R²", "0.992"),
            ("sim E: mean MAE", "4.423"),
            ("sim E: σ MAE", "0.262"),
            ("best (synth E1): mean MAE", "0.036"),
            ("best (synth E1): σ MAE", "0.003"),
        ),
        line=1941,
    ),
    ThesisItem(
        key="Table 4.4",
        caption=_GRID_CAPTION + "XGB.",
        section="4.3.1",
        stage="train",
        shows=(
            "Best gradient-boosted trees (XGB): high mean R² for most targets but the largest errors of "
            "the four families, above all for the total energy E. The best XGB model is simulated E5."
        ),
        numbers=(
            ("real E: mean R²", "0.928"),
            ("real E: mean MAE", "8.05"),
            ("synth E: mean R²", "0.879"),
            ("synth E: mean MAE", "9.985"),
            ("sim E: mean R²", "0.968"),
            ("sim E: mean MAE", "8.575"),
            ("best (sim E5): mean MAE", "0.035"),
        ),
        line=1974,
    ),
    # ---- 4.3.2 Scores on the separate real-robot test set ---------------------------------------
    ThesisItem(
        key="Figure 4.11",
        caption="Scores on the test set for E1",
        section="4.3.2",
        stage="train",
        shows=(
            "R² and MAE on the real-robot test set of XGB, PAR, SVR and MLP trained on the real, "
            "simulated and synthetic datasets, for the energy of joint 1. PAR, SVR and MLP reach R² 1.0 "
            "on every dataset; XGB trails, with its largest error on simulated data."
        ),
        numbers=(
            ("real: MLP R²", "1.0"),
            ("real: MLP MAE", "0.03"),
            ("real: XGB R²", "0.98"),
            ("real: XGB MAE", "0.7"),
            ("sim: MLP MAE", "0.0"),
            ("sim: XGB R²", "0.92"),
            ("sim: XGB MAE", "1.49"),
            ("synth: MLP MAE", "0.02"),
            ("synth: XGB R²", "0.99"),
            ("synth: XGB MAE", "0.55"),
        ),
        line=2029,
    ),
    ThesisItem(
        key="Figure 4.12",
        caption="Scores on the test set for E2",
        section="4.3.2",
        stage="train",
        shows=(
            "Test-set scores for the energy of joint 2: PAR, SVR and MLP keep R² 1.0 on all three "
            "datasets while XGB reaches less. The first XGB figures the text quotes (R² 0.89, MAE 0.73) "
            "come without a dataset name; the real and simulated ones are named."
        ),
        numbers=(
            ("all datasets: PAR, SVR, MLP R²", "1.0"),
            ("unnamed dataset: XGB R²", "0.89"),
            ("unnamed dataset: XGB MAE", "0.73"),
            ("unnamed dataset: MLP MAE", "0.01"),
            ("real: XGB R²", "0.99"),
            ("real: XGB MAE", "0.38"),
            ("real: MLP MAE", "0.01"),
            ("sim: XGB R²", "0.88"),
            ("sim: XGB MAE", "1.16"),
            ("sim: MLP MAE", "0.0"),
        ),
        line=2053,
    ),
    ThesisItem(
        key="Figure 4.13",
        caption="Scores on the test set for E3",
        section="4.3.2",
        stage="train",
        shows=(
            "Test-set scores for the energy of joint 3: SVR, PAR and MLP reach R² 1.0 on all datasets, "
            "while XGB drops sharply on the synthetic dataset."
        ),
        numbers=(
            ("all datasets: SVR, PAR, MLP R²", "1.0"),
            ("real: XGB R²", "0.99"),
            ("real: XGB MAE", "0.51"),
            ("real: MLP MAE", "0.01"),
            ("sim: XGB R²", "0.91"),
            ("sim: XGB MAE", "0.61"),
            ("sim: MLP MAE", "0.0"),
            ("synth: XGB R²", "0.25"),
            ("synth: XGB MAE", "0.25"),
            ("synth: MLP MAE", "0.01"),
        ),
        line=2099,
    ),
    ThesisItem(
        key="Figure 4.14",
        caption="Scores on the test set for E4",
        section="4.3.2",
        stage="train",
        shows=(
            "Test-set scores for the energy of joint 4: all methods reach R² 1.0 except XGB on the "
            "simulated dataset, and MLP has the lowest MAE on every dataset."
        ),
        numbers=(
            ("real: all methods R²", "1.0"),
            ("real: XGB MAE", "0.1"),
            ("real: MLP MAE", "0.0"),
            ("sim: XGB R²", "0.98"),
            ("sim: XGB MAE", "0.25"),
            ("sim: MLP MAE", "0.0"),
            ("synth: XGB MAE", "0.08"),
            ("synth: MLP MAE", "0.0"),
        ),
        line=2116,
    ),
    ThesisItem(
        key="Figure 4.15",
        caption="Scores on the test set for E5",
        section="4.3.2",
        stage="train",
        shows=(
            "Test-set scores for the energy of joint 5: all methods reach R² 1.0 except XGB on the "
            "simulated dataset; MLP's MAE rounds to zero on every dataset."
        ),
        numbers=(
            ("real: all methods R²", "1.0"),
            ("real: XGB MAE", "0.1"),
            ("real: PAR, SVR MAE", "0.04"),
            ("real: MLP MAE", "0.0"),
            ("sim: XGB R²", "0.94"),
            ("sim: XGB MAE", "0.2"),
            ("sim: MLP MAE", "0.0"),
            ("synth: XGB MAE", "0.07"),
            ("synth: MLP MAE", "0.0"),
        ),
        line=2140,
    ),
    ThesisItem(
        key="Figure 4.16",
        caption="Scores on the test set for E6",
        section="4.3.2",
        stage="train",
        shows=(
            "Test-set scores for the energy of joint 6: every method reaches R² 1.0 on every dataset, "
            "and the MAE separates them, lowest for MLP."
        ),
        numbers=(
            ("all datasets: all methods R²", "1.0"),
            ("real: XGB MAE", "0.05"),
            ("real: MLP MAE", "0.01"),
            ("sim: XGB MAE", "0.04"),
            ("sim: MLP MAE", "0.0"),
            ("synth: XGB MAE", "0.06"),
            ("synth: MLP MAE", "0.01"),
        ),
        line=2158,
    ),
    ThesisItem(
        key="Figure 4.17",
        caption="Scores on the test set for E",
        section="4.3.2",
        stage="train",
        shows=(
            "Test-set scores for the total energy E. XGB has the lowest R² and by far the largest MAE; "
            "models trained on simulated data also err much more than those trained on real or synthetic "
            "data. The thesis selects MLP as the best model overall."
        ),
        numbers=(
            ("real: XGB R²", "0.93"),
            ("real: XGB MAE", "7.71"),
            ("real: MLP MAE", "0.03"),
            ("sim: XGB R²", "0.85"),
            ("sim: XGB MAE", "9.59"),
            ("sim: SVR MAE", "1.56"),
            ("sim: MLP MAE", "1.59"),
            ("synth: XGB R²", "0.93"),
            ("synth: XGB MAE", "9.08"),
            ("synth: MLP MAE", "0.03"),
        ),
        line=2182,
    ),
    # ---- 4.4 ML model against the Lagrange-Euler model ---------------------------------------
    ThesisItem(
        key="Figure 4.18",
        caption=(
            "An example of the score comparison between the ML-based and LE model, section of the test data"
        ),
        section="4.4",
        stage="train",
        shows=(
            "Predictions of the MLP trained on synthetic data and of the Lagrange-Euler (LE) model on a "
            "section of the test data. The MLP follows the real data nearly perfectly while LE shows "
            "significant errors; LE is also far slower and larger, too costly for a fitness function."
        ),
        numbers=(
            ("LE: time per prediction", "1.06 seconds"),
            ("LE: model size", "39.6 MB"),
            ("MLP: model size", "300 KB"),
        ),
        line=2194,
    ),
    # ---- 4.5 Optimization results ------------------------------------------------------------
    ThesisItem(
        key="Table 4.5",
        caption="The scores of the GA algorithms for given parameters, using a single-objective function.",
        section="4.5.1",
        stage="bench",
        shows=(
            "Mean improvement over the initial random path, and its σ, of the GA with Random, Average "
            "and Differential recombination for two crossover and two mutation (or scaling) settings, on "
            "500 random paths with population 100 and 250 generations. Random recombination with "
            "P(C)=0.95, P(M)=0.05 is best; a low mutation rate costs the most."
        ),
        numbers=(
            ("best: Random, P(C)=0.95, P(M)=0.05", "51.96%"),
            ("best: σ", "0.21"),
            ("Average, P(C)=0.9, P(M)=0.05", "50.35%"),
            ("Average: σ", "0.2"),
            ("Differential, P(C)=0.95, F=0.05", "39.33%"),
            ("Differential: σ", "0.25"),
            ("lowest: Random, P(C)=0.9, P(M)=0.01", "34.31%"),
            ("random paths", "500"),
            ("population × generations", "100 × 250"),
        ),
        line=2234,
    ),
    ThesisItem(
        key="Table 4.6",
        caption="The scores of the GA algorithms for given parameters, using a multi-objective function.",
        section="4.5.1",
        stage="bench",
        shows=(
            "The same grid with a multi-objective fitness (one model per joint): slightly lower "
            "improvements, best again with Random recombination, P(C)=0.95, P(M)=0.05. The "
            "multi-objective GA is much slower (10 generations of 100 individuals)."
        ),
        numbers=(
            ("best: Random, P(C)=0.95, P(M)=0.05", "50.15%"),
            ("best: σ", "0.23"),
            ("Average, P(C)=0.90, P(M)=0.05", "48.85%"),
            ("Average: σ", "0.22"),
            ("Differential, P(C)=0.95, F=0.05", "37.84%"),
            ("Differential: σ", "0.27"),
            ("time, single-objective GA", "9.35 seconds"),
            ("time, multi-objective GA", "26.82 s"),
        ),
        line=2256,
    ),
    ThesisItem(
        key="Figure 4.19",
        caption="Comparison of path improvements for two applied local search strategies",
        section="4.5.2",
        stage="bench",
        shows=(
            "Improvement of the memetic algorithm (the best GA plus a local search) with randomized "
            "local search around the best candidate and with informed search that shrinks the "
            "parameters of the first two joints. Informed search improves more and runs faster; the "
            "randomized variant converges in fewer generations."
        ),
        numbers=(
            ("MA, randomized search", "52.59%"),
            ("MA, randomized search: σ", "0.21"),
            ("MA, informed search", "59.79%"),
            ("MA, informed search: σ", "0.18"),
            ("time, randomized MA", "20.12 seconds"),
            ("time, informed MA", "9.56 seconds"),
        ),
        line=2276,
    ),
    ThesisItem(
        key="Table 4.7",
        caption=(
            "Comparison of few randomly selected paths, between the energy use of a linear point-to-point "
            "movement and the optimized path."
        ),
        section="4.5.3",
        stage="optimize",
        shows=(
            "Energy measured on the real ABB IRB 120 for the default linear move (E_L) and the optimized "
            "path (E_O) on five randomly selected paths; the thesis reports significant energy savings "
            "against the linear path. The text version garbles the numeric cells (each split over two "
            "rows); only the third path reads consistently, so only it is recorded."
        ),
        # Printed as "92.20", "25 16" and "72 71" (decimal points lost in extraction);
        # (92.20 - 25.16) / 92.20 = 72.71 %, so the three cells agree.
        numbers=(
            ("path 3: E_L", "92.20"),
            ("path 3: E_O", "25.16"),
            ("path 3: Δ [%]", "72.71"),
        ),
        line=2288,
    ),
)

_BY_KEY: dict[str, ThesisItem] = {item.key: item for item in THESIS_ITEMS}


def thesis_item(key: str) -> ThesisItem:
    """Return the thesis item with the given key.

    Parameters
    ----------
    key : str
        ``"Table 4.1"`` … ``"Table 4.7"`` or ``"Figure 4.1"`` … ``"Figure 4.19"``.

    Returns
    -------
    ThesisItem

    Raises
    ------
    InvalidInput
        If no item has that key; the message lists the valid keys.

    Examples
    --------
    >>> item = thesis_item("Table 4.5")
    >>> item.stage, item.section
    ('bench', '4.5.1')
    >>> item.numbers[0]
    ('best: Random, P(C)=0.95, P(M)=0.05', '51.96%')
    """
    try:
        return _BY_KEY[key]
    except KeyError:
        raise InvalidInput(f"no thesis item {key!r}; expected one of: {', '.join(_BY_KEY)}") from None


def items_for_stage(stage: str) -> tuple[ThesisItem, ...]:
    """Return the items a pipeline stage reproduces, in thesis order.

    Parameters
    ----------
    stage : str
        One of :data:`STAGES`.

    Returns
    -------
    tuple of ThesisItem
        Possibly empty (no item belongs to ``"data"``).

    Raises
    ------
    InvalidInput
        If ``stage`` is not one of :data:`STAGES`.

    Examples
    --------
    >>> [item.key for item in items_for_stage("optimize")]
    ['Table 4.7']
    """
    if stage not in STAGES:
        raise InvalidInput(f"unknown stage {stage!r}; expected one of: {', '.join(STAGES)}")
    return tuple(item for item in THESIS_ITEMS if item.stage == stage)
