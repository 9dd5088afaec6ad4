# Sourced by the fault scripts (study_faults.sh, reference_faults.sh, kill_anywhere.sh) after
# they read their arguments: `fail` (message to stderr, exit 1), the Python that checks the
# outputs, and the work folder made afresh and entered.
#
#   source fault_script_start.sh WORK_DIR
py=/usr/bin/python3
fail() { echo "FAIL: $*" >&2; exit 1; }
rm -rf "$1"
mkdir -p "$1"
cd "$1"
