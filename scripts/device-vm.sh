#!/usr/bin/env bash
# Runs one command on a machine with the kernel devices a vehicle computer has and this one does
# not: a virtual machine (QEMU) with Debian's kernel and
#   - a KMS screen: a virtio GPU whose screen is connected (/dev/dri/card0);
#   - four V4L2 capture devices: vivid, the kernel's virtual video test driver (its test patterns;
#     the first and third through the single-planar API, the others through the multi-planar one);
#   - a CAN bus: vcan0, up.
# so that the outputs, cameras and vehicle signals can be tried through the real kernel interfaces.
# The machine sees this one's files read-only (9p) and runs the command in them as root, in the
# same folder and environment, with a writable temporary folder ($TMPDIR). About 7 s to boot, on
# QEMU's emulated CPU.
#
#   scripts/device-vm.sh fetch            Debian's kernel, downloaded once into build/device-vm
#   scripts/device-vm.sh run CMD [ARG..]  the command's exit status is this script's; its output
#                                         is the machine's console
#   scripts/device-vm.sh check            exit 0 when `run` can work here, else 77 and why
#
# Needs qemu-system-x86, busybox-static, kmod and cpio (Debian packages;
# scripts/install-deps.sh --device-vm). DEVICE_VM_DIR overrides where the kernel is kept;
# DEVICE_VM_KVM=1 uses KVM (not by default: nested KVM is often there and broken).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
store=${DEVICE_VM_DIR:-$root/build/device-vm}
kernel_package=linux-image-amd64

kernel_tree() { find "$store/kernel/lib/modules" -mindepth 1 -maxdepth 1 -type d 2>/dev/null | head -1; }

fetch() {
  [[ -n "$(kernel_tree)" ]] && return 0
  mkdir -p "$store"
  local work
  work=$(mktemp -d "$store/fetch.XXXXXX")
  # The metapackage names the current kernel; its image package holds vmlinuz and the modules.
  local image
  image=$(apt-cache depends "$kernel_package" | awk '/Depends: linux-image-/ {print $2; exit}')
  [[ -n "$image" ]] || { echo "device-vm: apt knows no $kernel_package" >&2; exit 1; }
  (cd "$work" && apt-get download "$image" >/dev/null 2>&1) ||
    { echo "device-vm: cannot download $image (apt-get download)" >&2; exit 1; }
  dpkg-deb -x "$work"/*.deb "$work/tree"
  depmod -b "$work/tree" "$(ls "$work/tree/lib/modules")"
  rm -rf "$store/kernel" && mv "$work/tree" "$store/kernel" && rm -rf "$work"
}

missing() {
  command -v qemu-system-x86_64 >/dev/null || { echo "qemu-system-x86_64 (qemu-system-x86)"; return; }
  [[ -x /bin/busybox ]] || { echo "/bin/busybox (busybox-static)"; return; }
  command -v modprobe >/dev/null || { echo "modprobe (kmod)"; return; }
  command -v cpio >/dev/null || { echo "cpio (cpio)"; return; }
  [[ -n "$(kernel_tree)" ]] || { echo "a kernel in $store ($0 fetch)"; return; }
}

# The initramfs: busybox, the modules for virtio, 9p, the GPU, vivid and vcan, and an init that
# mounts this machine's files and runs the command in them.
make_initramfs() {
  local modules=$1 out=$2 dir
  dir=$(mktemp -d)
  mkdir -p "$dir"/{bin,host,modules,proc,sys,dev}
  cp /bin/busybox "$dir/bin/"
  local version
  version=$(basename "$modules")
  local order=()
  for module in virtio_pci 9p 9pnet_virtio virtio-gpu vivid vcan can-raw; do
    while read -r _ path; do
      local name
      name=$(basename "$path")
      [[ " ${order[*]} " == *" $name "* ]] && continue
      cp "$path" "$dir/modules/"
      order+=("$name")
    done < <(modprobe -d "$store/kernel" -S "$version" --show-depends "$module")
  done
  cat >"$dir/init" <<EOF
#!/bin/busybox sh
/bin/busybox --install -s /bin
mount -t proc proc /proc; mount -t sysfs sys /sys; mount -t devtmpfs dev /dev
for m in ${order[*]}; do
  case \$m in
    vivid.ko) options="n_devs=4 node_types=0x1,0x1,0x1,0x1 multiplanar=1,2,1,2" ;;
    *) options="" ;;
  esac
  insmod /modules/\$m \$options || echo "device-vm: cannot load \$m"
done
ip link add dev vcan0 type vcan && ip link set up vcan0
mount -t 9p -o trans=virtio,version=9p2000.L,ro host /host || echo "device-vm: no host files"
mount -t proc proc /host/proc; mount -t sysfs sys /host/sys; mount -t devtmpfs dev /host/dev
# The only writable place, the one folder shared back: in the guest's own /dev (this machine's
# /tmp stays as it is, read-only: the command may live there).
mkdir /host/dev/device-vm
mount -t 9p -o trans=virtio,version=9p2000.L out /host/dev/device-vm
i=0; while [ ! -e /dev/dri/card0 ] && [ \$i -lt 50 ]; do sleep 0.1; i=\$((i+1)); done
chroot /host /bin/bash /dev/device-vm/command; echo \$? > /host/dev/device-vm/status
sync; poweroff -f
EOF
  chmod +x "$dir/init"
  (cd "$dir" && find . | cpio -o -H newc --quiet | gzip -1) >"$out"
  rm -rf "$dir"
}

run() {
  local why
  why=$(missing || true)
  [[ -z "$why" ]] || { echo "device-vm: cannot run here: it needs $why" >&2; exit 77; }
  local modules
  modules=$(kernel_tree)
  shared=$(mktemp -d)
  trap 'rm -rf "$shared"' EXIT
  make_initramfs "$modules" "$shared/initramfs.gz"
  # The command as run here: the same environment (sanitizers' options, a test filter) and folder;
  # its temporary files in the shared folder.
  {
    export -p | grep -v -E '^declare -x (HOME|PWD|OLDPWD|SHLVL|TMPDIR)='
    echo 'mkdir -p /dev/device-vm/tmp && export TMPDIR=/dev/device-vm/tmp'
    printf 'cd %q\nexec' "$PWD"
    printf ' %q' "$@"
    echo
  } >"$shared/command"
  local accel=(-accel tcg)
  [[ -n "${DEVICE_VM_KVM:-}" ]] && accel=(-accel kvm)
  qemu-system-x86_64 "${accel[@]}" -m 2048 -smp 2 -nographic -nodefaults -serial stdio -no-reboot \
    -kernel "$store/kernel/boot/vmlinuz-$(basename "$modules")" -initrd "$shared/initramfs.gz" \
    -append "console=ttyS0 quiet panic=-1" \
    -device virtio-gpu-pci -vga none -display none \
    -virtfs local,path=/,mount_tag=host,security_model=none,readonly=on,multidevs=remap \
    -virtfs "local,path=$shared,mount_tag=out,security_model=none,multidevs=remap" \
    </dev/null
  [[ -f "$shared/status" ]] || { echo "device-vm: the machine ended without the command's status" >&2; exit 1; }
  exit "$(cat "$shared/status")"
}

case "${1:-}" in
  fetch) fetch ;;
  check) why=$(missing || true); [[ -z "$why" ]] || { echo "device-vm: cannot run here: it needs $why"; exit 77; } ;;
  run) shift; run "$@" ;;
  *) echo "usage: $0 fetch | check | run CMD [ARG...]" >&2; exit 2 ;;
esac
