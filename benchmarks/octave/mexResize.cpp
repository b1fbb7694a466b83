// dcfkit's GNU Octave stand-in for the authors' compiled mexResize (their mexResize.cpp needs
// mexopencv's MxArray, which is not built here).
//
//   out = mexResize(im, [rows cols])             OpenCV bilinear (INTER_LINEAR)
//   out = mexResize(im, [rows cols], 'linear')   the same
//   out = mexResize(im, [rows cols], 'antialias')  area averaging (INTER_AREA)
//   out = mexResize(im, [rows cols], 'auto')     INTER_LINEAR when cols > size(im, 1), else INTER_AREA
//
// 'auto' follows what the compiled mex does, not what its comment says: it builds the new size
// as (width = cols, height = rows) and tests newSize.width > oldSize.height, assuming a
// transposed Mat, but MxArray::toMat hands the image over untransposed, so oldSize.height is
// the old number of ROWS (see dcfkit.patches.resize_auto). On square patches this is "when the
// width grows"; on the DSST's non-square scale samples it is not.
//
// im: uint8, single or double, rows x cols x channels (column-major, as Octave stores it); each
// channel is resized on its own and the class is kept. The size is read as integers (truncated).
#include "mex.h"
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

namespace {

template <typename T>
void resize_channels(const mxArray *src, int out_rows, int out_cols, int method, int cv_depth, mxArray **dst) {
  const mwSize ndim = mxGetNumberOfDimensions(src);
  const mwSize *dims = mxGetDimensions(src);
  const int rows = (int)dims[0], cols = (int)dims[1];
  mwSize channels = 1;
  for (mwSize k = 2; k < ndim; ++k) channels *= dims[k];

  // output keeps every dimension beyond the second
  mwSize *out_dims = (mwSize *)mxMalloc(ndim * sizeof(mwSize));
  out_dims[0] = (mwSize)out_rows; out_dims[1] = (mwSize)out_cols;
  for (mwSize k = 2; k < ndim; ++k) out_dims[k] = dims[k];
  *dst = mxCreateNumericArray(ndim, out_dims, mxGetClassID(src), mxREAL);
  mxFree(out_dims);

  const T *in = (const T *)mxGetData(src);
  T *out = (T *)mxGetData(*dst);
  const size_t in_plane = (size_t)rows * cols, out_plane = (size_t)out_rows * out_cols;
  cv::Mat plane(rows, cols, CV_MAKETYPE(cv_depth, 1)), resized;
  for (mwSize c = 0; c < channels; ++c) {
    const T *p = in + c * in_plane;
    for (int i = 0; i < rows; ++i) {  // column-major -> row-major
      T *row = plane.ptr<T>(i);
      for (int j = 0; j < cols; ++j) row[j] = p[i + (size_t)j * rows];
    }
    cv::resize(plane, resized, cv::Size(out_cols, out_rows), 0, 0, method);
    T *q = out + c * out_plane;
    for (int i = 0; i < out_rows; ++i) {  // row-major -> column-major
      const T *row = resized.ptr<T>(i);
      for (int j = 0; j < out_cols; ++j) q[i + (size_t)j * out_rows] = row[j];
    }
  }
}

int size_element(const mxArray *a, mwSize k) {
  switch (mxGetClassID(a)) {
    case mxDOUBLE_CLASS: return (int)((const double *)mxGetData(a))[k];
    case mxSINGLE_CLASS: return (int)((const float *)mxGetData(a))[k];
    case mxINT32_CLASS: return (int)((const int *)mxGetData(a))[k];
    case mxUINT8_CLASS: return (int)((const unsigned char *)mxGetData(a))[k];
    default: mexErrMsgTxt("mexResize: the size must be double, single, int32 or uint8");
  }
  return 0;
}

}  // namespace

void mexFunction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[]) {
  if (nrhs < 2 || nrhs > 3) mexErrMsgTxt("mexResize: usage out = mexResize(im, [rows cols] [, method])");
  if (nlhs > 1) mexErrMsgTxt("mexResize: one output");
  if (mxGetNumberOfElements(prhs[1]) < 2) mexErrMsgTxt("mexResize: the size needs two elements");
  const int out_rows = size_element(prhs[1], 0), out_cols = size_element(prhs[1], 1);
  if (out_rows < 1 || out_cols < 1) mexErrMsgTxt("mexResize: the size must be positive");
  const int old_rows = (int)mxGetDimensions(prhs[0])[0];

  int method = cv::INTER_LINEAR;
  if (nrhs == 3) {
    if (!mxIsChar(prhs[2])) mexErrMsgTxt("mexResize: the method must be a string");
    char *name = mxArrayToString(prhs[2]);
    const std::string m(name);
    mxFree(name);
    if (m == "antialias") method = cv::INTER_AREA;
    else if (m == "linear") method = cv::INTER_LINEAR;
    else if (m == "auto") method = out_cols > old_rows ? cv::INTER_LINEAR : cv::INTER_AREA;
    else mexErrMsgTxt("mexResize: method must be linear (default), antialias or auto");
  }

  switch (mxGetClassID(prhs[0])) {
    case mxUINT8_CLASS: resize_channels<unsigned char>(prhs[0], out_rows, out_cols, method, CV_8U, &plhs[0]); break;
    case mxSINGLE_CLASS: resize_channels<float>(prhs[0], out_rows, out_cols, method, CV_32F, &plhs[0]); break;
    case mxDOUBLE_CLASS: resize_channels<double>(prhs[0], out_rows, out_cols, method, CV_64F, &plhs[0]); break;
    default: mexErrMsgTxt("mexResize: the image must be uint8, single or double");
  }
}
