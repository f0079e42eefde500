# Counts the guest instructions a qemu-user run executed, from its `-d in_asm,exec,nochain` log:
# every translated block is listed once (IN: …, one line per instruction) and every execution of a
# block logs one Trace line with its guest pc (nochain: chained blocks log too). The sum over the
# Trace lines of their block's instruction count is the dynamic instruction count.
function key(hex) { sub(/^0x/, "", hex); sub(/^0+/, "", hex); return hex }
/^IN:/ { inblock = 1; start = ""; n = 0; next }
inblock && /^0x[0-9a-f]+:/ {
  if (start == "") start = key(substr($1, 1, length($1) - 1))
  ++n
  next
}
inblock && !/^0x/ { if (start != "") size[start] = n; inblock = 0 }
/^Trace / {
  split($4, f, "/")
  pc = key(f[2])
  if (!(pc in size)) ++unknown
  total += size[pc]
}
END { printf "%d %d\n", total, unknown + 0 }
