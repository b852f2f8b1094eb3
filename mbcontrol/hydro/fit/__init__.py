"""Radiation fitting, from the body-frame dataset to a stable, passive state-space model: the kernel
K(jω) and K(t) (`kernel`), the coupled fit (`radiation`, `vector_fit`, `group_fit`), judged by the device's
response (`response_error`) or the kernel's own error (`fit_error`), passivity (`passivity`,
`passive_order`, `sdp`), column-by-column fits for large arrays (`array_fit`, `array_passivity`),
a Hankel baseline (`baseline`), state-space forms (`ssforms`) and the fits' store on disk, shipped
or cached, where a fit made for another device serves if it meets the tolerance (`store`). Uses
the data stage only."""
