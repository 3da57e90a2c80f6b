"""LiAISON crosslink navigation scenarios reproducing the seed studies.

* :mod:`.orbits` - halo orbits by period, lunar orbiter (CRTBP);
* :mod:`.crosslink` - two-spacecraft CRTBP crosslink problem for the fit;
* :mod:`.pair` - one experiment: simulation, Monte Carlo trial, CRLB, Gramian;
* :mod:`.turan` - scenario 2 (Turan et al.: range-only vs range-rate-only);
* :mod:`.baseline` - scenario 1 (Fujimoto et al. sec. 2.1: GEO + L1 halo);
* :mod:`.doppler` - scenario 1b (Fujimoto et al. secs. 3-4: two-way crosslink Doppler, high fidelity);
* :mod:`.dowr` - scenario 3 (Li et al.: DRO-LEO dual one-way ranging, Table 13);
* :mod:`.ground` - scenario 4 (Leonard's thesis sec. 8.1: ground tracking with and without LiAISON);
* :mod:`.ground_mesh` - its trade study (Fig. 8.4 mesh of schedules, Fig. 8.9 scheduling offset);
* :mod:`.report` - tables and convergence plots of a scenario run;
* :mod:`.config` - scenario configurations (file entries relative to the TOML).

Run with ``odpipe liaison runs/liaison_X.toml -o DIR``.
"""
