!> The compensated state of the bodies (METHOD.md 3) and its arithmetic: time,
!> positions, velocities and the ledger integrals are sums of many step increments, each
!> kept as a value and its rounding error (the _lo parts).
module impact1d_state
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp
  use impact1d_lanes, only: max_lanes
  implicit none
  private
  public :: state_type, lane_state_type, load_lanes, new_state, take_state, add_compensated, accumulate, &
    renormalise, finite_state, constant_step, constant_steps, product_error, copy_scalars

  !> Time, positions, velocities and the ledger integrals, compensated: a micrometre bounce
  !> near a wall at x = 10 m keeps its digits, and 10^6 steps of 1e-5 s do not drift the clock
  !> by 1e-10 s. This is what keeps polynomial scenes at rounding error whatever the step count.
  type :: state_type
    real(wp) :: t = 0.0_wp, t_lo = 0.0_wp
    real(wp), allocatable :: x(:), x_lo(:), v(:), v_lo(:)   !< (N) positions, velocities
    real(wp) :: work = 0.0_wp, work_lo = 0.0_wp, friction_loss = 0.0_wp, friction_lo = 0.0_wp
    real(wp) :: impact_loss = 0.0_wp
    !> What the dampers dissipated (scenes with dampers only).
    real(wp) :: damping_loss = 0.0_wp, damping_lo = 0.0_wp
    !> What the prescribed motion of moving grounds did on the bodies (scenes with one only).
    real(wp) :: drive_work = 0.0_wp, drive_lo = 0.0_wp
  contains
    !> A state assigned to another of the same size is copied into its arrays: the intrinsic
    !> assignment of a type with allocatable components frees and allocates every one of
    !> them, which a step (b = a) and a trial step did each time (type-bound, so every user
    !> of the type has it).
    procedure, private :: copy_state
    generic :: assignment(=) => copy_state
  end type state_type

  !> A state in lanes (impact1d_lanes' max_lanes; a lane past N idle at 0): what a step and
  !> its location work on, and the run's state from its start on (run loads it from the
  !> N-long start once); fixed-size, it needs no descriptors and holds two bodies in one
  !> register.
  type :: lane_state_type
    real(wp) :: t = 0.0_wp, t_lo = 0.0_wp
    real(wp), dimension(max_lanes) :: x = 0.0_wp, x_lo = 0.0_wp, v = 0.0_wp, v_lo = 0.0_wp
    real(wp) :: work = 0.0_wp, work_lo = 0.0_wp, friction_loss = 0.0_wp, friction_lo = 0.0_wp
    real(wp) :: impact_loss = 0.0_wp
    real(wp) :: damping_loss = 0.0_wp, damping_lo = 0.0_wp
  end type lane_state_type

contains

  !> The state of n bodies at rest at 0, at t = 0 (the run's one allocation of it).
  pure subroutine new_state(n, s)
    integer, intent(in) :: n
    type(state_type), intent(inout) :: s
    if (allocated(s%x)) deallocate(s%x, s%x_lo, s%v, s%v_lo)
    allocate(s%x(n), s%x_lo(n), s%v(n), s%v_lo(n))
    s%x = 0.0_wp
    s%x_lo = 0.0_wp
    s%v = 0.0_wp
    s%v_lo = 0.0_wp
  end subroutine new_state

  !> to = from, into to's arrays when they have from's size (the run's one allocation kept).
  pure subroutine copy_state(to, from)
    class(state_type), intent(inout) :: to
    type(state_type), intent(in) :: from
    if (.not. allocated(from%x)) then
      if (allocated(to%x)) deallocate(to%x, to%x_lo, to%v, to%v_lo)
    else
      if (allocated(to%x)) then
        if (size(to%x) /= size(from%x)) deallocate(to%x, to%x_lo, to%v, to%v_lo)
      end if
      if (.not. allocated(to%x)) allocate(to%x(size(from%x)), to%x_lo(size(from%x)), &
        to%v(size(from%x)), to%v_lo(size(from%x)))
      to%x(:) = from%x
      to%x_lo(:) = from%x_lo
      to%v(:) = from%v
      to%v_lo(:) = from%v_lo
    end if
    call copy_scalars(to, from)
  end subroutine copy_state

  !> to = from without copying the arrays: they are swapped (from is left with to's old
  !> arrays' values, not to be read: a trial step's end taken as the run's state). Up to
  !> swap_values bodies value by value (the four moves of allocations, twelve move_alloc,
  !> cost more than that: 80 instructions a step of one body, 5% of a one-body scene's
  !> step; a loop of copies would be four calls to memcpy), beyond by moving the allocations.
  pure subroutine take_state(to, from)
    type(state_type), intent(inout) :: to, from
    integer, parameter :: swap_values = 8
    integer :: i
    if (size(to%x) <= swap_values .and. size(from%x) == size(to%x)) then
      do i = 1, size(to%x)
        call swap_value(to%x(i), from%x(i))
        call swap_value(to%x_lo(i), from%x_lo(i))
        call swap_value(to%v(i), from%v(i))
        call swap_value(to%v_lo(i), from%v_lo(i))
      end do
    else
      call swap(to%x, from%x)
      call swap(to%x_lo, from%x_lo)
      call swap(to%v, from%v)
      call swap(to%v_lo, from%v_lo)
    end if
    call copy_scalars(to, from)
  end subroutine take_state

  !> a and b swapped by moving their allocations (no element copied).
  pure subroutine swap(a, b)
    real(wp), allocatable, intent(inout) :: a(:), b(:)
    real(wp), allocatable :: held(:)
    call move_alloc(a, held)
    call move_alloc(b, a)
    call move_alloc(held, b)
  end subroutine swap

  !> a and b swapped.
  elemental subroutine swap_value(a, b)
    real(wp), intent(inout) :: a, b
    real(wp) :: held
    held = a
    a = b
    b = held
  end subroutine swap_value

  !> The clock and the ledger of from into to.
  pure subroutine copy_scalars(to, from)
    class(state_type), intent(inout) :: to
    type(state_type), intent(in) :: from
    to%t = from%t
    to%t_lo = from%t_lo
    to%work = from%work
    to%work_lo = from%work_lo
    to%friction_loss = from%friction_loss
    to%friction_lo = from%friction_lo
    to%impact_loss = from%impact_loss
    to%damping_loss = from%damping_loss
    to%damping_lo = from%damping_lo
    to%drive_work = from%drive_work
    to%drive_lo = from%drive_lo
  end subroutine copy_scalars

  !> hi + lo += increment: the exact rounding error of hi + increment (Knuth's two-sum, valid
  !> whichever is larger) goes into lo; then hi takes what of lo it can hold (Fast2Sum), so
  !> hi alone is the sum correctly rounded (event times and samples read hi) and lo stays
  !> below half an ulp of it.
  elemental subroutine add_compensated(hi, lo, increment)
    real(wp), intent(inout) :: hi, lo
    real(wp), intent(in) :: increment
    call accumulate(hi, lo, increment)
    call renormalise(hi, lo)
  end subroutine add_compensated

  !> hi += increment, its exact rounding error (two-sum) into lo; hi + lo is the sum.
  elemental subroutine accumulate(hi, lo, increment)
    real(wp), intent(inout) :: hi, lo
    real(wp), intent(in) :: increment
    real(wp) :: total, rounded
    total = hi + increment
    rounded = total - hi
    lo = lo + ((hi - (total - rounded)) + (increment - rounded))
    hi = total
  end subroutine accumulate

  !> The exact rounding error of the product a b: a b - fl(a b) (Dekker's two-product with
  !> Veltkamp's split, no fused multiply-add: the build passes -ffp-contract=off; exact
  !> while a b neither overflows nor underflows). A gear ratio's gap x_b - n x_a needs it.
  elemental real(wp) function product_error(a, b) result(error)
    real(wp), intent(in) :: a, b
    real(wp), parameter :: split = 134217729.0_wp     ! 2^27 + 1
    real(wp) :: a_hi, a_lo, b_hi, b_lo, c
    c = split * a
    a_hi = c - (c - a)
    a_lo = a - a_hi
    c = split * b
    b_hi = c - (c - b)
    b_lo = b - b_hi
    error = (((a_hi * b_hi - a * b) + a_hi * b_lo) + a_lo * b_hi) + a_lo * b_lo
  end function product_error

  !> hi becomes hi + lo correctly rounded and lo what is left (Fast2Sum, exact while |lo| is
  !> below |hi|, as it is but for a sum passing through zero).
  elemental subroutine renormalise(hi, lo)
    real(wp), intent(inout) :: hi, lo
    real(wp) :: total
    total = hi + lo
    lo = lo - (total - hi)
    hi = total
  end subroutine renormalise

  !> The bodies' step of h under the constant acceleration a: RK4 is exact there, and its
  !> step is the quadratic x + h v + h^2 a / 2, v + h a; both sums compensated and
  !> renormalised. On the parts, not the state, so that a loop can keep them in registers;
  !> the clock is the caller's (a step to a stop sets it to the stop).
  pure subroutine constant_step(h, a, x, x_lo, v, v_lo)
    real(wp), intent(in) :: h, a(max_lanes)
    real(wp), dimension(max_lanes), intent(inout) :: x, x_lo, v, v_lo
    call add_compensated(x, x_lo, h * ((v + v_lo) + (0.5_wp * h) * a))
    call add_compensated(v, v_lo, h * a)
  end subroutine constant_step

  !> n steps of h under the constant velocity change dv per step (half_dv = dv / 2): RK4's
  !> closed form, the sums accumulated but not renormalised (the low parts carry the
  !> rounding meanwhile; the caller renormalises once at the end). Kept here, next to
  !> accumulate, so the compiler inlines it into this hottest loop. The bodies in max_lanes
  !> lanes (fixed-size arrays, unpack_motion's): the compiler keeps them in registers
  !> through the loop and takes the lanes' chains of additions side by side.
  pure subroutine constant_steps(n, h, dv, half_dv, t, t_lo, x, x_lo, v, v_lo)
    integer(int64), intent(in) :: n
    real(wp), intent(in) :: h, dv(max_lanes), half_dv(max_lanes)
    real(wp), intent(inout) :: t, t_lo, x(max_lanes), x_lo(max_lanes), v(max_lanes), v_lo(max_lanes)
    integer(int64) :: j
    real(wp) :: t_, t_lo_, x_(max_lanes), x_lo_(max_lanes), v_(max_lanes), v_lo_(max_lanes)
    ! Local copies: the compiler keeps them in registers through the loop.
    t_ = t
    t_lo_ = t_lo
    x_ = x
    x_lo_ = x_lo
    v_ = v
    v_lo_ = v_lo
    do j = 1, n
      call accumulate(t_, t_lo_, h)
      call accumulate(x_, x_lo_, h * ((v_ + v_lo_) + half_dv))
      call accumulate(v_, v_lo_, dv)
    end do
    t = t_
    t_lo = t_lo_
    x = x_
    x_lo = x_lo_
    v = v_
    v_lo = v_lo_
  end subroutine constant_steps

  !> ls = s in lanes (a lane past N at 0). Lane by lane in a loop of max_lanes trips: moves
  !> the compiler unrolls (a loop of N trips became calls to memcpy).
  pure subroutine load_lanes(s, ls)
    type(state_type), intent(in) :: s
    type(lane_state_type), intent(out) :: ls
    integer :: i
    ls%t = s%t
    ls%t_lo = s%t_lo
    do i = 1, max_lanes
      if (i > size(s%x)) exit
      ls%x(i) = s%x(i)
      ls%x_lo(i) = s%x_lo(i)
      ls%v(i) = s%v(i)
      ls%v_lo(i) = s%v_lo(i)
    end do
    ls%work = s%work
    ls%work_lo = s%work_lo
    ls%friction_loss = s%friction_loss
    ls%friction_lo = s%friction_lo
    ls%impact_loss = s%impact_loss
    ls%damping_loss = s%damping_loss
    ls%damping_lo = s%damping_lo
  end subroutine load_lanes

  !> All of the state a run reports is finite.
  pure logical function finite_state(x, v, work)
    real(wp), intent(in) :: work
    real(wp), contiguous, intent(in) :: x(:), v(:)
    finite_state = all(abs(x) <= huge(1.0_wp)) .and. all(abs(v) <= huge(1.0_wp)) .and. &
      abs(work) <= huge(1.0_wp)
  end function finite_state
end module impact1d_state
