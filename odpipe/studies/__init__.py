"""Studies: the seed papers' navigation scenarios reproduced on the library, apart from its core.

Nothing in the library imports this package (``tests/test_layers.py``). Each scenario module has a
``run(cfg, out, log)`` and a configuration kind in :mod:`.scenarios`; ``odpipe study
runs/study_X.toml -o DIR`` runs it and writes the paper-vs-odpipe report.

Scenarios (the module name says what is studied; the paper in brackets):

* :mod:`.halo_geo_crtbp` - an L1 halo and a GEO satellite tracked only by each other, CRTBP
  range and range-rate (Fujimoto et al. 2012, sec. 2.1);
* :mod:`.halo_geo_doppler` - the same pair with two-way crosslink Doppler and high-fidelity
  dynamics, S and X band, and the S band with the halo's state known (Fujimoto et al. 2012, secs. 3-4,
  Tables 4-6);
* :mod:`.formation_observability` - range-only against range-rate-only crosslinks for halo/halo and
  halo/lunar-orbiter formations: Gramian measures, Monte Carlo, CRLB (Turan et al. 2022, Table 1);
* :mod:`.dro_leo_dowr` - DRO-LEO dual one-way ranging with clocks (Li et al. 2023, Table 13);
* :mod:`.ground_and_crosslink` - ground tracking of a halo orbiter and a GEO satellite with and
  without crosslinks (Leonard 2015, sec. 8.1);
* :mod:`.schedule_trade` - the mesh of (crosslink gap, ground gap) schedules and the pass offset
  on that set-up (Leonard 2015, secs. 8.1.2.3-8.1.2.4);
* :mod:`.lunar_orbiter_search` - which lunar orbiters of the paper's period reproduce Table 1's
  lunar columns (a script, ``python -m odpipe.studies.lunar_orbiter_search``).

Building blocks: :mod:`.crtbp_orbits` (halos by period, Keplerian orbiters), :mod:`.crtbp_problem`
(the two-spacecraft CRTBP crosslink problem for the fit), :mod:`.crosslink_pair` (one experiment:
simulation, Monte Carlo trial, CRLB, Gramian), :mod:`.ekf` (the single-pass EKF the Fujimoto paper used,
beside odpipe's filter-smoother), :mod:`.study_report` (tables, plots, spreads over open choices),
:mod:`.scenarios` (the configuration kinds, loaded strictly).
"""
