# SPDX-License-Identifier: MIT
# Sourced by the tools' scripts (the benchmarks, soak.sh): their options, each setting variables,
# read in one loop. POSIX sh (bench_bus.sh, bench_emu.sh and soak.sh are sh scripts).
#
#   . "$root/tools/script_options.sh"
#   script_options "usage: tools/x.sh [--seed S] [--quick]" "--seed=seed --quick=quick:1" "$@" || exit 2
#
# Each word of the second argument is one option: --opt=var takes a value (var=VALUE),
# --opt=var1,var2 takes two (--seeds FIRST COUNT), --opt=var:V takes none and sets var to V.
# An unknown option, or one missing its value, prints the usage line on stderr and returns 2.
script_options() {
    so_usage_=$1 so_specs_=$2
    shift 2
    while [ $# -gt 0 ]; do
        so_found_=
        for so_spec_ in $so_specs_; do
            [ "$1" = "${so_spec_%%=*}" ] || continue
            so_found_=1 so_vars_=${so_spec_#*=}
            shift
            case $so_vars_ in
                *:*) eval "${so_vars_%%:*}=\${so_vars_#*:}" ;;
                *)
                    for so_var_ in $(echo "$so_vars_" | tr , ' '); do
                        [ $# -gt 0 ] || { echo "$so_usage_" >&2; return 2; }
                        eval "$so_var_=\$1"
                        shift
                    done
                    ;;
            esac
            break
        done
        [ -n "$so_found_" ] || { echo "$so_usage_" >&2; return 2; }
    done
}
