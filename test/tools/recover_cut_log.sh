#!/usr/bin/env bash
# Usage: recover_cut_log.sh COLOC SCENARIO
# A recording whose recorder died: the twin's log as MCAP, cut in the middle of a chunk. coloc fuse
# refuses it and says how to read it; with --recover it fuses the messages before the cut, and
# coloc convert --recover turns it into a closed recording that fuses to the same trajectory.
source "$(dirname "$0")/simulated_drive.sh"
"$coloc" convert "$work/sim/log" "$work/whole.mcap" > /dev/null
size=$(stat -c %s "$work/whole.mcap")
head -c $((size * 2 / 3)) "$work/whole.mcap" > "$work/cut.mcap"
fuse=("$coloc" fuse --map "$work/sim/map" --config "$work/sim/fuse.yaml")

if "${fuse[@]}" "$work/cut.mcap" --out "$work/refused" > "$work/refused.txt" 2>&1; then
  echo "FAIL: a cut recording was fused without --recover"; exit 1
fi
grep -q 'cut.mcap: .*truncated.*--recover' "$work/refused.txt" || { echo "FAIL: the refusal does not say how to read it:"; cat "$work/refused.txt"; exit 1; }

"${fuse[@]}" "$work/cut.mcap" --recover --out "$work/recovered" | tee "$work/recovered.txt"
read -r messages read_bytes < <(sed -n 's/.*cut.mcap: not closed; recovered \([0-9]*\) messages from its first \([0-9]*\) of.*/\1 \2/p' "$work/recovered.txt")
[ -n "${messages:-}" ] || { echo "FAIL: no line saying what was recovered"; exit 1; }
all=$(sed -n 's/^converted \([0-9]*\) messages.*/\1/p' < <("$coloc" convert "$work/sim/log" "$work/again.mcap"))
awk -v m="$messages" -v a="$all" 'BEGIN { exit !(m > 0 && m < a) }' || { echo "FAIL: recovered $messages of $all messages"; exit 1; }
awk -v r="$read_bytes" -v s="$size" 'BEGIN { exit !(r > 0 && r <= s * 2 / 3) }' || { echo "FAIL: read $read_bytes bytes of a $size-byte file cut at 2/3"; exit 1; }
grep -q "^  $messages messages over" "$work/recovered.txt" || { echo "FAIL: the replay did not read the $messages messages recovered"; exit 1; }
grep -q '"recovered"' "$work/recovered/summary.json" || { echo "FAIL: summary.json does not list the recovered file"; exit 1; }
grep -q 'position error vs ground truth' "$work/recovered.txt" || { echo "FAIL: no error against ground truth"; exit 1; }

"$coloc" convert --recover "$work/cut.mcap" "$work/repaired.mcap" | tee "$work/convert.txt"
grep -q "^converted $messages messages" "$work/convert.txt" || { echo "FAIL: the repaired file does not hold the $messages messages"; exit 1; }
"${fuse[@]}" "$work/repaired.mcap" --out "$work/repaired" > /dev/null
cmp "$work/recovered/fused.tum" "$work/repaired/fused.tum" || { echo "FAIL: the repaired recording fuses differently"; exit 1; }
if grep -q '"recovered"' "$work/repaired/summary.json"; then echo "FAIL: the repaired recording is still not closed"; exit 1; fi
echo "recovered $messages of $all messages ($read_bytes of $size bytes); the repaired recording fuses to the same trajectory"
