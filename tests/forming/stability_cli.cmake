# Command-line tests of `simform stability` (ctest names forming.cli.stability.*), included by
# tests/forming_cli_tests.cmake, whose sf_forming_cli_test() they use:
#  - the command lines of docs/forming.md, "Buckling stability" (output folders under build/);
#  - exit code 1 for bad input, naming the option or FILE:LINE:COLUMN, with no output folder;
#  - exit code 2 for wrong usage.

set(sf_stab ${SF_FORMING_CLI_DIR}/stability)
file(MAKE_DIRECTORY ${sf_stab})

# docs/forming.md: the sample input file, with the pictures (no display needed).
sf_forming_cli_test(stability.docs_sample
  COMMAND stability data/forming/stability/pp_glass_45.yaml --out ${sf_stab}/stability_45
  REMOVE ${sf_stab}/stability_45
  STDOUT "most unstable mode: wave direction 135\\.0 deg.*verdict: UNSTABLE"
  EXISTS "${sf_stab}/stability_45/growth_rate.csv|${sf_stab}/stability_45/summary.json|${sf_stab}/stability_45/stability_map_thickening.png|${sf_stab}/stability_45/stability_map_thinning.png|${sf_stab}/stability_45/growth_rate_direction.png")
# docs/forming.md: everything from options.
sf_forming_cli_test(stability.docs_options
  COMMAND stability --fibres 30,-30 --viscosity 2e-3 --thickness 2 --shear-rate 0.5 --tensions 0.01,0.004
          --out ${sf_stab}/stability_30 --no-plots
  REMOVE ${sf_stab}/stability_30
  STDOUT "verdict: stable"
  EXISTS "${sf_stab}/stability_30/growth_rate.csv|${sf_stab}/stability_30/summary.json"
  ABSENT ${sf_stab}/stability_30/stability_map_thinning.png)

# Bad input: exit 1, the message names the option or the place in the file, no output.
set(sf_stab_opts --viscosity 2e-3 --thickness 2 --shear-rate 0.5 --tensions 0.01,0.004)
sf_forming_cli_test(stability.negative_viscosity
  COMMAND stability --fibres 30,-30 --viscosity -1 --thickness 2 --shear-rate 0.5 --tensions 0.01,0.004
          --out ${sf_stab}/bad1 --no-plots
  EXIT 1 STDERR "--viscosity: expected a positive viscosity \\(MPa s\\), found -1" ABSENT ${sf_stab}/bad1)
sf_forming_cli_test(stability.degenerate_fibres
  COMMAND stability --fibres 30,210 ${sf_stab_opts} --out ${sf_stab}/bad2 --no-plots
  EXIT 1 STDERR "--fibres: the fibre families at 30 and 210 deg are parallel" ABSENT ${sf_stab}/bad2)
sf_forming_cli_test(stability.rates_stretch_fibres
  COMMAND stability --fibres 30,-30 --viscosity 2e-3 --thickness 2 --rates 1,1,0 --tensions 0.01,0.004
          --out ${sf_stab}/bad3 --no-plots
  EXIT 1 STDERR "--rates: .*stretches the fibres" ABSENT ${sf_stab}/bad3)
sf_forming_cli_test(stability.rate33_compressible
  COMMAND stability --fibres 30,-30 --viscosity 2e-3 --thickness 2 --rates 1,-3,0 --rate33 1 --tensions 0.01,0.004
          --out ${sf_stab}/bad4 --no-plots
  EXIT 1 STDERR "--rate33: .*violates incompressibility" ABSENT ${sf_stab}/bad4)
file(WRITE ${sf_stab}/bad.yaml "fibres: [30, -30]\nviscosity: 2.0e-3\nthickness: -2\nshear_rate: 0.5\ntensions: {T_a: 0.01, T_b: 0.004}\n")
sf_forming_cli_test(stability.bad_yaml_value
  COMMAND stability ${sf_stab}/bad.yaml --out ${sf_stab}/bad5 --no-plots
  EXIT 1 STDERR "bad\\.yaml:3:12: expected a positive thickness \\(mm\\), found -2" ABSENT ${sf_stab}/bad5)
# A required key missing from the file: its place and name (issue 20).
file(WRITE ${sf_stab}/no_viscosity.yaml "# no viscosity\nfibres: [30, -30]\nthickness: 2\nshear_rate: 0.5\ntensions: {T_a: 0.01, T_b: 0.004}\n")
sf_forming_cli_test(stability.missing_key
  COMMAND stability ${sf_stab}/no_viscosity.yaml --out ${sf_stab}/bad6 --no-plots
  EXIT 1 STDERR "no_viscosity\\.yaml:2:1: stability input: missing required key 'viscosity' \\(or give --viscosity\\)"
  ABSENT ${sf_stab}/bad6)

# Wrong usage: exit 2.
sf_forming_cli_test(stability.no_out COMMAND stability --fibres 30,-30 ${sf_stab_opts} EXIT 2 STDERR "--out")
sf_forming_cli_test(stability.no_fibres
  COMMAND stability ${sf_stab_opts} --out ${sf_stab}/usage1 EXIT 2 STDERR "--fibres is required" ABSENT ${sf_stab}/usage1)
sf_forming_cli_test(stability.fibres_count
  COMMAND stability --fibres 30 ${sf_stab_opts} --out ${sf_stab}/usage2
  EXIT 2 STDERR "--fibres: expected 2 comma-separated numbers" ABSENT ${sf_stab}/usage2)
