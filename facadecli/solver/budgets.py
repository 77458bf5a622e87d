"""The solver's budgets and tolerances, in one place: every limit on effort is counted in
work (states visited, letters laid, words made), never in seconds, so that the same spec
gives the same layout on any machine; a limit that cuts a search makes its answer
unproven (the report says so), never "impossible"."""

from __future__ import annotations

import math
import time

INF = math.inf


def safety_clock() -> float:
    """The clock of the safety net (``solver.time_limit``): this process's CPU seconds, not
    the wall's, so that a loaded machine (other processes taking turns on its cores) does
    not make it fire sooner and change an answer. Deadlines are ``safety_clock() + limit``."""
    return time.process_time()


# -- the policy of one axis (solver.axis) ----------------------------------------------
EXACT_WORK = 40_000  # work units of the exact searches of one axis (see solver.exact)
HEURISTIC_WORK = 5_000  # search states of the heuristic alignment per axis
EXACT_SHARE = 16_000  # work units at most of one candidate's search in one pass
TIE_SHARE = 500  # ... and of a search for a layout that can only tie with the best
# objectives (m^2) the passes of the exact search look within, the last one without limit
DEEPENING = (0.05, 0.2, 0.8, 3.2, 12.8, 51.2, INF)
CANDIDATE_LIMIT = 500  # candidates generated per axis (more are not looked at)
FEASIBLE_TO_COMPARE = 6  # candidates that align, compared by the sizing objective
EFFORT_FLOOR = 2000  # search states any candidate may use once one has aligned
EFFORT_FACTOR = 4  # ... or this many times what the first that aligned needed
TIE = 1e-11  # objectives this close, relative to the canvas squared (and never less than
# TIE m^2), are equally good: numerical noise (SPEC 2.7: 4.5e-8 m^2 on a 67 m façade, where
# an element 0.2 mm off its size already counts); its tie-breaks decide among them
PERFECT_REACH = 1.0 + 1e-9  # words looked at for a perfect layout: those the canvas holds
CONSTRUCTIONS = 16  # candidates laid out by construction, least bound first, until one fits
VARIANTS = 48  # options of a cluster of patterns tried in place of the best layout's
FITTED = 2000  # options of a cluster tried for a fit to the rows at the back (cheap tests)
WORDS_FITTED = (
    200  # words of one pattern tried for that fit when its cluster is chosen a pattern at a time
)
SWEEPS = 2  # passes over the clusters while a variant improves the best layout
TRIED = 3  # of a cluster's options that fit, those laid out (least covering first)
NEAR_CANVAS = 1e-9  # a word this close to the canvas (relative) fits it at preferred sizes
REPAIRS = 3  # passes fitting the clusters to the backs, those in conflict first
NEAR_EQUAL = 0.05  # m^2 of squared deviation: alternatives this close to the best are offered
TIER = 0.01  # candidates needing up to this share of the canvas more than the first that
# aligns (in tolerance, or in room made by opaque letters) still compete with it
CANDIDATES_TO_TRY = 200

# -- the exact search (solver.exact) -------------------------------------------------------
LEAF_WORK = 20  # work units of sizing a complete layout (a bound costs 1)
COMBINATION_WORK = 64  # partial columns built per work unit
RECURSION_MARGIN = 1000  # frames beyond the search's deepest path (the callers', numpy's)
SAME = 1e-9  # objectives this close are equal (the tie-breaks decide)

# -- the heuristic alignment of the paper (solver.alignment) ------------------------------
TARGETS_PER_STATE = 24  # target widths tried from one state, smallest first
MAX_NODES = 5_000  # states one search may visit before it gives up on a candidate
JOINT_ROWS = 2  # rows searched together; more are added one at a time
REFINE_NODES = 200  # least extra effort spent looking for a cheaper path than the first
BUDGET_STEP = 0.01  # least deepening of the error budget, as a share of the canvas

# -- layouts by construction (solver.construct) ----------------------------------------
NEAR = 1e-7  # metres (times the canvas, at least 1 m): boundaries this close are one
# tolerances (shares of the shortest letter) within which boundaries laid at the
# relaxation's sizes are taken for one cut; the QP then makes them meet
SNAP = (0.0, 0.1, 0.25, 0.45)
ROUNDS = 3  # constructions at solved sizes after the first
# weight of the relaxation's placeholders and gaps: it only makes the optimum unique (a
# larger one moves the sizes, and so the boundaries the rows are cut at)
FAINT = 1e-12
FITTING_WORK = 2000  # letters laid at most while fitting one row's placeholders

# -- the words and candidates of an axis (solver.candidates) -------------------------------
WORDS_PER_PATTERN = 4000  # words looked at per pattern
OPTIONS_PER_CLUSTER = 2000  # joint choices kept per cluster of patterns sharing counters
MAX_LETTERS = 400  # longest word with a counter considered (longer: the answer is unproven)
FINITE_LETTERS = 20_000  # longest word of a pattern without counters (all of them are made)
