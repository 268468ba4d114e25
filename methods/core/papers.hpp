// Papers that more than one variant rests on, as BibTeX entries: a variant
// whose paper is here refers to it (`bibtex = papers::sulsky1994`) instead of
// repeating it; a paper of one variant stays in that variant's own header.
#pragma once

#include <string_view>

namespace mpmtb::papers {

// The MPM with the linear hat and PIC transfer, and the small-strain material
// of its colliding disks (transfers/pic.hpp, kernels/linear.hpp,
// models/linear_elastic.hpp).
inline constexpr std::string_view sulsky1994 = R"bib(@article{sulsky1994,
  author = {Sulsky, Deborah and Chen, Zhen and Schreyer, Howard L.},
  title = {A particle method for history-dependent materials},
  journal = {Computer Methods in Applied Mechanics and Engineering},
  volume = {118},
  number = {1--2},
  pages = {179--196},
  year = {1994},
  doi = {10.1016/0045-7825(94)90112-0}
})bib";

// Quadrature errors of MPM and the B-spline kernels (kernels/quadratic.hpp,
// kernels/cubic.hpp).
inline constexpr std::string_view steffen2008 = R"bib(@article{steffen2008,
  author = {Steffen, Michael and Kirby, Robert M. and Berzins, Martin},
  title = {Analysis and reduction of quadrature errors in the material point method ({MPM})},
  journal = {International Journal for Numerical Methods in Engineering},
  volume = {76},
  number = {6},
  pages = {922--948},
  year = {2008},
  doi = {10.1002/nme.2360}
})bib";

}  // namespace mpmtb::papers
