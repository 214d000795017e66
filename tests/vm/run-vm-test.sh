#!/usr/bin/env bash
# Runs uinput_device_tests, v4l2_source_vm_tests and the daemon on a real Linux kernel: Debian's own kernel
# package (downloaded with apt-get, extracted, never installed) boots under QEMU (TCG, no KVM needed) into a
# busybox initramfs with systemd-udevd, the input rules, libinput, evemu, dbus-daemon and the kernel's
# virtual video driver vivid. All cases run in one boot. Exit 0 iff the guest reports "VMTEST RESULT: PASS".
#
# The daemon replays a recording in the guest that the same daemon makes here first from the simulated rig
# --recording-rig names (rendering under emulation would take minutes); it is kept in DIR/recording while the
# daemon binary and the rig stay the same.
#
# usage: run-vm-test.sh --work DIR --test BINARY --v4l2-test BINARY --daemon BINARY --rules DIR
#                       --recording-rig sim:SPEC [--gtest-filter FILTER]
# --gtest-filter: the cases to run in both test binaries (GoogleTest's filter syntax; default all)
# environment: EVERYTOUCH_VM_CACHE  where the kernel is kept between runs (default: DIR/cache)
#              EVERYTOUCH_VM_KERNEL_PACKAGE  a linux-image-* package to use instead of linux-image-amd64's
#              EVERYTOUCH_VM_TIMEOUT  seconds the guest may run (default 600)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)

work="" test_binary="" v4l2_test_binary="" daemon="" rules="" recording_rig="" gtest_filter=""
while [ $# -gt 0 ]; do
    case "$1" in
    --work) work=$2; shift 2 ;;
    --test) test_binary=$2; shift 2 ;;
    --v4l2-test) v4l2_test_binary=$2; shift 2 ;;
    --daemon) daemon=$2; shift 2 ;;
    --rules) rules=$2; shift 2 ;;
    --recording-rig) recording_rig=$2; shift 2 ;;
    --gtest-filter) gtest_filter=$2; shift 2 ;;
    *) echo "run-vm-test.sh: unknown argument $1" >&2; exit 2 ;;
    esac
done
[ -n "$work" ] && [ -x "$test_binary" ] && [ -x "$v4l2_test_binary" ] && [ -x "$daemon" ] && [ -d "$rules" ] &&
    [ -n "$recording_rig" ] || {
    echo "usage: run-vm-test.sh --work DIR --test BINARY --v4l2-test BINARY --daemon BINARY --rules DIR" \
        "--recording-rig sim:SPEC" >&2
    exit 2
}

fail() { echo "run-vm-test.sh: $*" >&2; exit 1; }
need() { command -v "$1" >/dev/null || fail "$1 is missing (Debian package $2; tools/dev.sh installs it)"; }
need qemu-system-x86_64 qemu-system-x86
need busybox busybox-static
need cpio cpio
need xz xz-utils
need libinput libinput-tools
need evemu-record evemu-tools
need udevadm udev
need dbus-daemon dbus
need apt-get apt
need strip binutils
busybox=$(command -v busybox)
ldd "$busybox" >/dev/null 2>&1 && fail "$busybox is not static: install busybox-static"

started=$(date +%s.%N)
mkdir -p "$work"
work=$(cd "$work" && pwd)
cache=${EVERYTOUCH_VM_CACHE:-$work/cache}
mkdir -p "$cache"

# --- the kernel: linux-image-amd64's current dependency, cached by package name ---
package=${EVERYTOUCH_VM_KERNEL_PACKAGE:-}
if [ -z "$package" ]; then
    resolve() { apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ {print $2; exit}'; }
    package=$(resolve)
    if [ -z "$package" ]; then
        echo "apt knows no linux-image-amd64 yet: apt-get update"
        apt-get update -qq || true
        package=$(resolve)
    fi
    [ -n "$package" ] || package=$(ls "$cache" | grep -m1 '^linux-image-' || true)
    [ -n "$package" ] || fail "cannot find the kernel package linux-image-amd64 depends on"
fi
version=${package#linux-image-}
kernel_dir=$cache/$package
# The modules the guest loads, in the order it loads them (each after what it depends on): the input devices,
# then the media core and vivid.
modules=(drivers/input/evdev drivers/input/misc/uinput
    drivers/media/mc/mc drivers/media/v4l2-core/videodev drivers/media/common/videobuf2/videobuf2-common
    drivers/media/common/videobuf2/videobuf2-memops drivers/media/common/videobuf2/videobuf2-v4l2
    drivers/media/common/videobuf2/videobuf2-vmalloc drivers/media/common/videobuf2/videobuf2-dma-contig
    drivers/media/v4l2-core/v4l2-dv-timings drivers/media/common/v4l2-tpg/v4l2-tpg drivers/media/rc/rc-core
    drivers/media/cec/core/cec drivers/media/test-drivers/vivid/vivid)
module_list="${modules[*]}"
if [ ! -f "$kernel_dir/ready" ] || [ "$(cat "$kernel_dir/ready")" != "$module_list" ]; then
    echo "fetching $package"
    rm -rf "$kernel_dir"
    mkdir -p "$kernel_dir/deb" "$kernel_dir/root"
    (cd "$kernel_dir/deb" && apt-get download "$package" >/dev/null 2>&1) || fail "apt-get download $package failed"
    patterns=("./boot/vmlinuz-$version")
    for module in "${modules[@]}"; do patterns+=("./lib/modules/$version/kernel/$module.ko*"); done
    dpkg-deb --fsys-tarfile "$kernel_dir"/deb/*.deb | tar -x -C "$kernel_dir/root" --wildcards "${patterns[@]}"
    mkdir -p "$kernel_dir/modules"
    : >"$kernel_dir/modules/order"
    for module in "${modules[@]}"; do
        file=$(ls "$kernel_dir"/root/lib/modules/"$version"/kernel/"$module".ko* | head -1)
        name=$(basename "$module").ko
        case "$file" in
        *.xz) xz -dc "$file" >"$kernel_dir/modules/$name" ;;
        *.zst) zstd -qdc "$file" >"$kernel_dir/modules/$name" ;;
        *) cp "$file" "$kernel_dir/modules/$name" ;;
        esac
        echo "$name" >>"$kernel_dir/modules/order"
    done
    # The bzImage carries the kernel as an XZ stream; its uncompressed ELF (with a PVH entry) boots faster,
    # skipping the firmware's real-mode start and the decompression under emulation.
    kernel=$kernel_dir/root/boot/vmlinuz-$version
    offset=$(LC_ALL=C grep -obUaP '\xfd7zXZ\x00' "$kernel" | head -1 | cut -d: -f1 || true)
    if [ -n "$offset" ]; then
        tail -c +$((offset + 1)) "$kernel" | xz -dc --single-stream >"$kernel_dir/vmlinux" 2>/dev/null || true
    fi
    head -c 4 "$kernel_dir/vmlinux" 2>/dev/null | grep -q 'ELF' || cp "$kernel" "$kernel_dir/vmlinux"
    rm -rf "$kernel_dir/deb" "$kernel_dir/root/lib"
    echo "$module_list" >"$kernel_dir/ready"
fi
fetched=$(date +%s.%N)

# --- the recording the daemon replays in the guest ---
recording=$work/recording
stamp="$recording_rig $(sha256sum <"$daemon" | cut -d' ' -f1)"
if [ "$(cat "$recording.stamp" 2>/dev/null)" != "$stamp" ]; then
    echo "recording $recording_rig"
    rm -rf "$recording" "$recording.stamp"
    # No bus: a daemon running on this machine keeps its name.
    DBUS_SYSTEM_BUS_ADDRESS=unix:path=$work/no-bus \
        "$daemon" --rig "$recording_rig" --fast --record "$recording" >"$work/recording.log" 2>&1 || {
        cat "$work/recording.log" >&2; fail "everytouchd could not record $recording_rig"; }
    echo "$stamp" >"$recording.stamp"
fi
recorded=$(date +%s.%N)

# --- the initramfs: busybox, udev, libinput, evemu, our binaries and every library they load ---
root=$work/root
rm -rf "$root"
mkdir -p "$root"/usr/{bin,sbin,lib,lib64,local/bin} "$root"/{proc,sys,dev,run,tmp,etc,root}
for d in bin sbin lib lib64; do ln -s usr/$d "$root/$d"; done # merged /usr first, so copies land inside it
cp "$busybox" "$root/usr/bin/busybox"
for applet in $("$busybox" --list); do
    [ -e "$root/usr/bin/$applet" ] || ln -s busybox "$root/usr/bin/$applet"
done
copy_file() {
    mkdir -p "$root$(dirname "$1")"
    cp -L "$1" "$root$1"
}
copy_libraries() {
    for library in $(ldd "$1" 2>/dev/null | grep -oE '/[^ ]+'); do
        [ -e "$root$library" ] || copy_file "$library"
    done
}
copy_program() {
    copy_file "$1"
    copy_libraries "$1"
}
for program in /usr/bin/libinput /usr/libexec/libinput/libinput-{list-devices,debug-events} \
    /usr/bin/evemu-record /usr/bin/udevadm /usr/bin/dbus-daemon \
    /usr/lib/udev/libinput-device-group /usr/lib/udev/libinput-fuzz-extract /usr/lib/udev/libinput-fuzz-to-zero; do
    copy_program "$program"
done
mkdir -p "$root/usr/lib/systemd" "$root/usr/lib/udev/rules.d" "$root/usr/share" "$root/usr/lib/modules"
ln -s /usr/bin/udevadm "$root/usr/lib/systemd/systemd-udevd" # udevadm is multi-call
for rule in 50-udev-default 60-input-id 60-evdev 60-persistent-input 70-touchpad 80-libinput-device-groups \
    90-libinput-fuzz-override; do
    cp "/usr/lib/udev/rules.d/$rule.rules" "$root/usr/lib/udev/rules.d/"
done
cp "$rules"/*.rules "$root/usr/lib/udev/rules.d/"
cp -r /usr/share/libinput "$root/usr/share/" # libinput's quirks
cp "$kernel_dir"/modules/*.ko "$kernel_dir/modules/order" "$root/usr/lib/modules/"
# Without their debugging information: the initramfs unpacks into the guest's memory.
copy_ours() {
    strip --strip-debug -o "$root/usr/local/bin/$2" "$1"
    copy_libraries "$1"
}
copy_ours "$test_binary" uinput_device_tests
copy_ours "$v4l2_test_binary" v4l2_source_vm_tests
copy_ours "$daemon" everytouchd
mkdir -p "$root/usr/local/share/everytouch"
cp -r "$recording" "$root/usr/local/share/everytouch/recording"
echo 'root:x:0:0:root:/root:/bin/sh' >"$root/etc/passwd"
printf 'root:x:0:\ninput:x:101:\n' >"$root/etc/group"
cp "$here/init" "$root/init"
chroot "$root" /usr/bin/udevadm --version >/dev/null || fail "the initramfs misses a library of udevadm"
# Uncompressed: unpacking is faster than decompressing under emulation.
(cd "$root" && find . | cpio -o -H newc --quiet) >"$work/initramfs.cpio"
packed=$(date +%s.%N)

# --- boot ---
console=$work/console.log
echo "booting $package ($(du -h "$work/initramfs.cpio" | cut -f1) initramfs)"
set +e
timeout --foreground -k 5 "${EVERYTOUCH_VM_TIMEOUT:-600}" qemu-system-x86_64 \
    -accel tcg,thread=multi -cpu max -smp 2 -m 1536 \
    -kernel "$kernel_dir/vmlinux" -initrd "$work/initramfs.cpio" \
    -append "console=ttyS0 quiet loglevel=3 panic=-1 rdinit=/init${gtest_filter:+ GTEST_FILTER=$gtest_filter}" \
    -nographic -no-reboot -nodefaults -serial stdio -monitor none </dev/null | tr -d '\r' | tee "$console"
qemu_status=${PIPESTATUS[0]}
set -e
finished=$(date +%s.%N)
awk -v s="$started" -v f="$fetched" -v r="$recorded" -v p="$packed" -v e="$finished" -v q="$qemu_status" 'BEGIN {
    printf "vm timings: kernel %.1f s, recording %.1f s, initramfs %.1f s, guest %.1f s, total %.1f s (qemu exit %d)\n",
        f - s, r - f, p - r, e - p, e - s, q }'
grep -q '^VMTEST RESULT: PASS' "$console"
