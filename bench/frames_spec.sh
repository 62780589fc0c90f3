# Sourced by the long-traffic benches (long_traffic.sh, check_compare_scaling.sh): the default link
# spec (2 m, capacitor isolation, BQ7961x at both ends) with N repeated stack-write commands,
# down direction.
#   write_frames_spec N FILE
write_frames_spec() {
  local n=$1 i
  {
    echo "name: cap-$n"
    echo "cable: {length: 2}"
    printf 'stimulus:\n  direction: down\n  frames:\n'
    for ((i = 0; i < n; ++i)); do echo '    - "stack-write reg=0x0100 data=02B778BC"'; done
  } >"$2"
}
