!> The compensated state of the bodies (METHOD.md 3) and its arithmetic: time,
!> positions, velocities and the ledger integrals are sums of many step increments, each
!> kept as a value and its rounding error (the _lo parts).
module impact1d_state
  use impact1d_kinds, only: wp
  implicit none
  private
  public :: state_type, new_state, take_state, add_compensated, accumulate, renormalise, finite_state, &
    product_error, copy_scalars

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

  !> All of the state a run reports is finite.
  pure logical function finite_state(x, v, work)
    real(wp), intent(in) :: work
    real(wp), contiguous, intent(in) :: x(:), v(:)
    finite_state = all(abs(x) <= huge(1.0_wp)) .and. all(abs(v) <= huge(1.0_wp)) .and. &
      abs(work) <= huge(1.0_wp)
  end function finite_state
end module impact1d_state
