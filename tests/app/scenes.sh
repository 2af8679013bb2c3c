# The test scenes as preset files (tests/scenes; sourced by lib.sh and demo_lib.sh). Each names the
# keys its tests depend on over SimParams' defaults, so that a change to a preset changes no test
# but the preset's own. `cloth`: the seeds' cloth without contact.
scenes=$(cd "$(dirname "${BASH_SOURCE[0]}")/../scenes" && pwd)
cloth=(--preset-file "$scenes/cloth.json")
