#!/bin/bash
# Optional parity tool: runs the authors' own MATLAB code, STRCF (run_STRCF.m, hand-crafted:
# gray + fHOG + CN), DR²Track (IROS version, DR2Track1), BACF (the ARCF repository's
# tracker_HOG.m with its aberrance term off, which is BACF_optimized.m), ARCF-HC (run_ARCF.m:
# gray + fHOG + CN, tracker_HOGCN.m), AutoTrack (run_AutoTrack.m, AutoTrack_optimized.m), ECO-HC
# (runfiles/testing_ECO_HC.m, implementation/tracker.m) or CSR-DCF (read_default_csr_parameters.m,
# create_csr_tracker.m, track_csr_tracker.m) under GNU Octave on one dataset's sequences, and
# writes their boxes for comparison with dcfkit.
#
#   bash benchmarks/authors_octave.sh {strcf|dr2track|bacf|arcf|autotrack|eco_hc|csrdcf} DATASET_ROOT OUT_DIR [sequence ...]
#
# DATASET_ROOT is read by dcfkit.datasets (UAV123, UAV123@10fps, UAV123@20L, DTB70, UAVDT, OTB
# layouts; DATASET=otb names the layout where two fit, as the validation set's OUT/all). Writes OUT_DIR/<DATASET>/<sequence>.txt (1-based x,y,w,h, one '%.4f' line per frame)
# and OUT_DIR/<DATASET>/<tracker>_fps.tsv (the fps the authors' code reports, wall seconds).
# Needs: apt-get install -y octave liboctave-dev octave-image libopencv-imgproc-dev
# The authors' code comes from $DCFKIT_REFERENCE (default: ../shared/reference next to the repo),
# ECO's from $ECO_CODE (default $DCFKIT_REFERENCE/ECO: a checkout of martin-danelljan/ECO, checked
# at 27e8ae5) and CSR-DCF's from $CSR_CODE (default $DCFKIT_REFERENCE/csr-dcf: alanlukezic/csr-dcf,
# checked at 469959d), and is built into $AUTHORS_BUILD (default: a new temp dir); it is never
# copied into dcfkit.
# What the built copy changes, only for portability (algorithms and parameters untouched):
#  - gradientMex.cpp (Piotr's toolbox) gets Octave's 64-bit mwSize and <cstdlib>/<cstddef>;
#  - mexResize is dcfkit's stand-in benchmarks/octave/mexResize.cpp (OpenCV resize per channel,
#    default/'linear' = INTER_LINEAR, 'antialias' = INTER_AREA) instead of their mexopencv build,
#    for every tracker (DR²Track's is rebuilt over the one setup_dr2track.sh makes). Its 'auto'
#    follows their compiled mex: INTER_LINEAR when the new width exceeds the old *height* (number
#    of rows; MxArray::toMat hands the image over untransposed), else INTER_AREA. Until
#    2026-11-25 the stand-in of $DCFKIT_REFERENCE/octave compared with the old width, which
#    differs on non-square patches only (the DSST scale samples of DR²Track, ARCF-HC, AutoTrack);
#  - hann, ifft2(..,'symmetric'), gather, mtimesx are the .m shims of $DCFKIT_REFERENCE/octave
#    (their mtimesx.m help file is moved aside so the shim is found). The ifft2 shim returns
#    real(ifft2(x)); MATLAB's 'symmetric' uses only half of x and may differ when x is not
#    conjugate-symmetric, as ARCF-HC's and AutoTrack's filters (complex ADMM h-steps) are not;
#  - DR²Track: built by $DCFKIT_REFERENCE/octave/setup_dr2track.sh (which applies the above,
#    with the old stand-in), then utils/mexResize.mex is replaced by dcfkit's;
#  - STRCF: its Piotr's-toolbox submodule is absent from the export, so fhog.m and
#    gradientMex.cpp/sse.hpp/wrappers.hpp come from the reference's DR2Track1/feature (the same
#    toolbox files; that fhog.m calls gradientMex directly, with the same arguments); and
#    benchmarks/octave/authors_run.m sets params.visualization = 0 after run_STRCF.m's settings;
#  - BACF and ARCF-HC: the ARCF repository's copy, with sse.hpp from DR2Track1/feature (absent
#    there) and gpuArray = the identity (benchmarks/octave/shims/gpuArray.m, into utils/:
#    tracker_HOGCN.m calls gpuArray(zeros(..)) whatever params.use_gpu says);
#    BACF: authors_run.m takes run_ARCF_H.m's settings and sets admm_gamma = 0 (no aberrance
#    term: the filter update is BACF's) and learning_rate = 0.013 (run_BACF.m's; ARCF uses 0.019);
#    ARCF-HC: authors_run.m takes run_ARCF.m's settings and sets params.visualization = 0;
#  - AutoTrack: its feature/ lacks sse.hpp and wrappers.hpp, which come from DR2Track1/feature
#    (the same toolbox files; its fhog.m and gradientMex.cpp are DR2Track1's); mexResize.mex
#    and the shims go into its utils/; run_AutoTrack.m runs as it is (visualization already 0).
#  - gradientMex's SSE estimates (rcpps, rsqrtps) and its acos table are the ones of dcfkit's fhog
#    arithmetic 'sse' (benchmarks/octave/portable_estimates.hpp; acos in double, rounded to float),
#    which every processor computes alike. With SSE_ESTIMATES=sse_cpu the processor's own
#    instructions and the C library's acosf stay, as in a MATLAB run on this machine (dcfkit's
#    'sse_cpu'): their values differ between processor families (docs/architecture.md).
#  - ECO-HC: its pdollar_toolbox submodule is empty, so fhog.m and gradientMex.cpp/sse.hpp/
#    wrappers.hpp come from DR2Track1/feature into external_libs/pdollar_toolbox/channels (the same
#    toolbox files: get_fhog.m and the scale filter call fhog(I, binSize[, nOrients]), which that
#    fhog.m serves with the same gradientMex calls); the prebuilt mexResize.mex* are replaced by
#    dcfkit's stand-in; mtimesx is their own mtimesx.c built by mkoctfile against Octave's BLAS,
#    without OpenMP, with -DMWSIZE_MAX (Octave's 64-bit mwSize) and mxCreateSharedDataCopy (a
#    MATLAB-internal call Octave lacks) = mxDuplicateArray (a copy of the same values); hann,
#    ifft2 and gather shims into utils/ (cifft2's 'symmetric' input is conjugate-symmetric: ECO
#    completes it with full_fourier_coeff), with benchmarks/octave/shims/ifft.m for the scale
#    filter's ifft(.., 'symmetric') (MATLAB's rule: the completion of the first half); authors_run.m
#    takes testing_ECO_HC.m's settings and sets params.visualization = 0. The HC setting uses no
#    matconvnet (its empty submodule).
#  - CSR-DCF: its mex files are built as compile.m does, into mex/: mex_src/hog/gradientMex.cpp
#    (the toolbox file: the patches above) and mex_segment, mex_extractforeground,
#    mex_extractbackground against OpenCV 4's core and imgproc (opencv2/opencv.hpp, which needs
#    every module, becomes core.hpp + imgproc.hpp; <map> and <vector> are included; CV_USRTYPE1,
#    gone from OpenCV 4, is its 2.4 value 7: no caller passes it). OpenCV 4's bit-exact 8-bit
#    bilinear cv::resize (segment.cpp's ROI) may differ from 2.4's by one grey level. MATLAB
#    functions: imresize is dcfkit's benchmarks/octave/shims/imresize.m (MATLAB's algorithm;
#    Octave's does not normalise the antialiasing weights, resizes columns first and rounds
#    integer images from single), hann the shim above, and strel a copy of Octave's image
#    package's @strel whose disk takes N = 0 below radius 3, as MATLAB's does (the package
#    refuses the default N = 4 of strel('disk', 1)). authors_run.m runs demo_csr.m's loop
#    without its display and reinitialisation: create_csr_tracker on the first frame with the
#    1-based box, track_csr_tracker on the others; fps = frames / seconds inside those calls.
set -euo pipefail
# Octave's BLAS (OpenBLAS) picks its kernels by processor, and they sum in different orders
# (rgb2gray's product differs in the last bit on a quarter of the pixels between Haswell and
# SkylakeX kernels): one kernel everywhere keeps the runs the same on every x86-64 machine with AVX2
export OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE:-Haswell}
[ $# -ge 3 ] || { sed -n '2,14p' "$0"; exit 2; }
case $1 in strcf|dr2track|bacf|arcf|autotrack|eco_hc|csrdcf) ;;
  *) echo "tracker must be strcf, dr2track, bacf, arcf, autotrack, eco_hc or csrdcf"; exit 2 ;; esac
TRK=$1; ROOT=$(cd "$2" && pwd); mkdir -p "$3"; OUT=$(cd "$3" && pwd); shift 3
HERE=$(cd "$(dirname "$0")" && pwd)
REF=$(cd "${DCFKIT_REFERENCE:-$HERE/../../shared/reference}" && pwd)
BUILD=${AUTHORS_BUILD:-$(mktemp -d /tmp/authors_octave.XXXXXX)}; mkdir -p "$BUILD"
command -v mkoctfile >/dev/null || { echo "needs: apt-get install -y octave liboctave-dev octave-image libopencv-imgproc-dev"; exit 1; }
# dcfkit's mexResize stand-in (the compiled mex's 'auto' rule), built to $1
build_mexresize() {
  mkoctfile --mex -O2 -I/usr/include/opencv4 -o "$1" "$HERE/octave/mexResize.cpp" -lopencv_imgproc -lopencv_core
}
# gradientMex with dcfkit's portable estimates and acos table (unless SSE_ESTIMATES=sse_cpu); $1: its folder
portable_estimates() {
  case ${SSE_ESTIMATES:-sse} in sse_cpu) return ;; sse) ;; *) echo "SSE_ESTIMATES must be sse or sse_cpu"; exit 2 ;; esac
  sed -i "s|^#include <emmintrin.h>.*|&\n#include \"$HERE/octave/portable_estimates.hpp\"|
          s|return _mm_rcp_ps(x);|return dcfkit_estimates::each<dcfkit_estimates::rcp>(x);|
          s|return _mm_rsqrt_ps(x);|return dcfkit_estimates::each<dcfkit_estimates::rsqrt>(x);|" "$1/sse.hpp"
  sed -i 's|a1\[i\]=float(acos(i/float(n)));|a1[i]=float(acos(double(i/float(n))));|' "$1/gradientMex.cpp"
  grep -q dcfkit_estimates::rsqrt "$1/sse.hpp" && grep -q 'acos(double(' "$1/gradientMex.cpp" \
    || { echo "could not put the portable estimates into $1"; exit 1; }
}
# Piotr's gradientMex, ported and built in its folder $1
port_gradientmex() {
  sed -i '1i #include <cstdlib>\n#include <cstddef>' "$1/wrappers.hpp"
  sed -i 's/const int dims\[3\]={h,w,d}, n=h\*w\*d;/const mwSize dims[3]={(mwSize)h,(mwSize)w,(mwSize)d}; const int n=h*w*d;/; s/  const int \*dims; int nDims;/  const mwSize *dims; int nDims;/' "$1/gradientMex.cpp"
  portable_estimates "$1"
  (cd "$1" && mkoctfile --mex -O2 -DMATLAB_MEX_FILE -o gradientMex.mex gradientMex.cpp)
}
# a checkout named by an environment variable ($1 its folder, $2 the variable, $3 the repository)
checkout() {
  [ -d "$1" ] || { echo "no checkout of $3 at $1: set $2 to one"; exit 1; }
}
# the portability patches the copies share (gradientMex folder, mexResize.mex path, mtimesx
# folder, shim folder)
port_lineage() {
  port_gradientmex "$1"
  build_mexresize "$2"
  mv "$3/mtimesx.m" "$3/mtimesx_mex_help.txt"
  cp "$REF"/octave/{hann.m,ifft2.m,gather.m,mtimesx.m} "$4/"
}
case $TRK in
  dr2track)
    bash "$REF/octave/setup_dr2track.sh" "$BUILD/code"
    rm -f "$BUILD/code/utils/mexResize.mex"; build_mexresize "$BUILD/code/utils/mexResize.mex"
    portable_estimates "$BUILD/code/feature"
    (cd "$BUILD/code/feature" && mkoctfile --mex -O2 -DMATLAB_MEX_FILE -o gradientMex.mex gradientMex.cpp) ;;
  strcf)
    C=$BUILD/code; P=$C/external_libs/pdollar_toolbox/channels
    rm -rf "$C"; cp -r "$REF/STRCF" "$C"; mkdir -p "$P"
    cp "$REF"/DR2Track/DR2Track1/feature/{fhog.m,gradientMex.cpp,sse.hpp,wrappers.hpp} "$P/"
    port_lineage "$P" "$C/external_libs/mexResize/mexResize.mex" "$C/external_libs/mtimesx" "$C/utils" ;;
  bacf|arcf)
    C=$BUILD/code; rm -rf "$C"; cp -r "$REF/ARCF" "$C"
    cp "$REF/DR2Track/DR2Track1/feature/sse.hpp" "$C/utils/"
    port_lineage "$C/utils" "$C/external_libs/mexResize/mexResize.mex" "$C/external_libs/mtimesx" "$C/utils"
    cp "$HERE/octave/shims/gpuArray.m" "$C/utils/" ;;
  autotrack)
    C=$BUILD/code; rm -rf "$C"; cp -r "$REF/AutoTrack" "$C"
    cp "$REF"/DR2Track/DR2Track1/feature/{sse.hpp,wrappers.hpp} "$C/feature/"
    port_lineage "$C/feature" "$C/utils/mexResize.mex" "$C/utils" "$C/utils" ;;
  eco_hc)
    C=$BUILD/code; P=$C/external_libs/pdollar_toolbox/channels; M=$C/external_libs/mtimesx
    checkout "${ECO_CODE:-$REF/ECO}" ECO_CODE martin-danelljan/ECO
    rm -rf "$C"; cp -r "${ECO_CODE:-$REF/ECO}" "$C"; rm -rf "$C/.git"; mkdir -p "$P"
    cp "$REF"/DR2Track/DR2Track1/feature/{fhog.m,gradientMex.cpp,sse.hpp,wrappers.hpp} "$P/"
    port_gradientmex "$P"
    rm -f "$C"/external_libs/mexResize/mexResize.mex*
    build_mexresize "$C/external_libs/mexResize/mexResize.mex"
    (cd "$M" && mkoctfile --mex -O2 -DDEFINEUNIX -DMWSIZE_MAX -DmxCreateSharedDataCopy=mxDuplicateArray \
       -o mtimesx.mex mtimesx.c -lblas > build.log 2>&1) || { cat "$M/build.log"; exit 1; }  # its many warnings
    mv "$M/mtimesx.m" "$M/mtimesx_mex_help.txt"
    cp "$REF"/octave/{hann.m,ifft2.m,gather.m} "$HERE/octave/shims/ifft.m" "$C/utils/" ;;
  csrdcf)
    C=$BUILD/code; S=$C/mex_src/segmentation; O=$C/octave_shims
    checkout "${CSR_CODE:-$REF/csr-dcf}" CSR_CODE alanlukezic/csr-dcf
    rm -rf "$C"; cp -r "${CSR_CODE:-$REF/csr-dcf}" "$C"; rm -rf "$C/.git"; mkdir -p "$C/mex" "$O"
    port_gradientmex "$C/mex_src/hog"; mv "$C/mex_src/hog/gradientMex.mex" "$C/mex/"
    sed -i 's|^#include <opencv2/opencv.hpp>|#include <opencv2/core.hpp>\n#include <opencv2/imgproc.hpp>|' \
      "$S"/*.cpp "$S/mex_utils.hpp" "$S/src/segment.h"
    sed -i '1i #include <map>\n#include <vector>' "$S/mex_utils.hpp"
    sed -i 's|(depth==CV_USRTYPE1)|(depth==7 /* CV_USRTYPE1 of OpenCV 2.4 */)|' "$S/mex_utils.hpp"
    for f in mex_segment mex_extractforeground mex_extractbackground; do
      (cd "$S" && mkoctfile --mex -O2 -Isrc -I/usr/include/opencv4 -o "$C/mex/$f.mex" "$f.cpp" src/segment.cpp \
         -lopencv_imgproc -lopencv_core)
    done
    cp "$REF/octave/hann.m" "$HERE/octave/shims/imresize.m" "$O/"
    cp -r "$(octave --no-gui -q --eval "pkg load image; disp(fileparts(which('strel')))" 2>/dev/null | tail -1)" "$O/"
    sed -i 's|^      ## TODO implement approximation by periodic lines|      if (radius < 3) n = 0; endif  # as MATLAB: no decomposition below radius 3\n&|' "$O/@strel/strel.m"
    grep -q 'if (radius < 3) n = 0;' "$O/@strel/strel.m" || { echo "could not patch the image package's strel"; exit 1; } ;;
esac
# frame lists and 1-based first boxes, from dcfkit's own dataset loader
DS=$(PYTHONPATH="$HERE/..${PYTHONPATH:+:$PYTHONPATH}" python3 - "$ROOT" "$BUILD/seqs" "$@" <<'EOF'
import os, sys, pathlib
from dcfkit.datasets import load_dataset
root, dest, names = sys.argv[1], pathlib.Path(sys.argv[2]), sys.argv[3:] or None
dest.mkdir(parents=True, exist_ok=True)
seqs = load_dataset(os.environ.get("DATASET") or None, root, names)
for s in seqs:
    (dest / f"{s.name}.frames").write_text("".join(f"{f}\n" for f in s.frames))
    x, y, w, h = s.init_box
    (dest / f"{s.name}.init").write_text(f"{x + 1},{y + 1},{w},{h}\n")
names = {"uav123": "UAV123", "uav123_10fps": "UAV123_10fps", "uav123_20l": "UAV123_20L",
         "dtb70": "DTB70", "uavdt": "UAVDT", "otb": "OTB"}
print(names.get(seqs[0].dataset, seqs[0].dataset), *(s.name for s in seqs))
EOF
)
set -- $DS; DSNAME=$1; shift
mkdir -p "$OUT/$DSNAME"; FPS=$OUT/$DSNAME/${TRK}_fps.tsv
[ -f "$FPS" ] || printf 'sequence\tframes\tfps\twall_s\n' > "$FPS"
for s in "$@"; do  # one Octave process at a time
  t0=$(date +%s.%N)
  log=$(octave --no-gui -q --eval "pkg load image; warning('off','all'); addpath('$HERE/octave'); authors_run('$TRK', '$BUILD/code', '$BUILD/seqs/$s.frames', '$BUILD/seqs/$s.init', '$OUT/$DSNAME/$s.txt')" 2>&1) || { echo "$log"; exit 1; }
  wall=$(echo "$(date +%s.%N) - $t0" | bc)
  fps=$(echo "$log" | sed -n 's/^fps \([0-9.eE+-]*\)$/\1/p' | tail -1)
  printf '%s\t%s\t%s\t%.1f\n' "$s" "$(wc -l < "$BUILD/seqs/$s.frames")" "$fps" "$wall" | tee -a "$FPS"
done
echo "boxes in $OUT/$DSNAME (build: $BUILD)"
