!> External forces f_i(t) = constant + table(t) + amp*sin(omega*t + phase), each term present
!> only when the scene names it, so an absent term costs nothing in the stepping loop.
module impact1d_forcing
  use impact1d_kinds, only: wp
  implicit none
  private
  public :: table_type, forcing_type

  !> A piecewise-linear force table: strictly increasing times, held constant outside.
  type :: table_type
    real(wp), allocatable :: t(:), f(:)
  end type table_type

  type :: forcing_type
    real(wp) :: constant(2) = 0.0_wp
    logical :: has_table(2) = .false.
    logical :: has_sine(2) = .false.
    type(table_type) :: table(2)
    real(wp) :: amp(2) = 0.0_wp, omega(2) = 0.0_wp, phase(2) = 0.0_wp
  contains
    procedure :: force
    procedure :: rate
    procedure :: next_breakpoint
    procedure :: is_polynomial
  end type forcing_type

contains

  !> Forces on both bodies at time t.
  pure function force(self, t) result(f)
    class(forcing_type), intent(in) :: self
    real(wp), intent(in) :: t
    real(wp) :: f(2)
    integer :: i
    f = self%constant
    do i = 1, 2
      if (self%has_table(i)) f(i) = f(i) + table_value(self%table(i), t)
      if (self%has_sine(i)) f(i) = f(i) + self%amp(i) * sin(self%omega(i) * t + self%phase(i))
    end do
  end function force

  !> Right derivative df/dt at t: tells which way a force that is exactly at a bound will go.
  pure function rate(self, t) result(df)
    class(forcing_type), intent(in) :: self
    real(wp), intent(in) :: t
    real(wp) :: df(2)
    integer :: i, k
    df = 0.0_wp
    do i = 1, 2
      if (self%has_table(i)) then
        k = segment(self%table(i)%t, t)
        if (k >= 1 .and. k < size(self%table(i)%t)) df(i) = &
          (self%table(i)%f(k + 1) - self%table(i)%f(k)) / (self%table(i)%t(k + 1) - self%table(i)%t(k))
      end if
      if (self%has_sine(i)) df(i) = df(i) + self%amp(i) * self%omega(i) * cos(self%omega(i) * t + self%phase(i))
    end do
  end function rate

  !> First table corner strictly after t (huge if none): steps end there exactly, because
  !> RK4 is exact for polynomial forcing only between corners.
  pure function next_breakpoint(self, t) result(t_next)
    class(forcing_type), intent(in) :: self
    real(wp), intent(in) :: t
    real(wp) :: t_next
    integer :: i, k
    t_next = huge(1.0_wp)
    do i = 1, 2
      if (.not. self%has_table(i)) cycle
      k = segment(self%table(i)%t, t) + 1
      if (k <= size(self%table(i)%t)) t_next = min(t_next, self%table(i)%t(k))
    end do
  end function next_breakpoint

  !> True when the forcing is polynomial between breakpoints (no sine term).
  pure logical function is_polynomial(self)
    class(forcing_type), intent(in) :: self
    is_polynomial = .not. any(self%has_sine)
  end function is_polynomial

  pure function table_value(table, t) result(f)
    type(table_type), intent(in) :: table
    real(wp), intent(in) :: t
    real(wp) :: f, s
    integer :: k, n
    n = size(table%t)
    k = segment(table%t, t)
    if (k < 1) then
      f = table%f(1)
    else if (k >= n) then
      f = table%f(n)
    else
      s = (t - table%t(k)) / (table%t(k + 1) - table%t(k))
      f = table%f(k) + s * (table%f(k + 1) - table%f(k))
    end if
  end function table_value

  !> Index k with times(k) <= t < times(k+1); 0 before the first time, n at or after the last.
  pure integer function segment(times, t) result(k)
    real(wp), intent(in) :: times(:)
    real(wp), intent(in) :: t
    integer :: lo, hi, mid
    lo = 0
    hi = size(times) + 1
    do while (hi - lo > 1)
      mid = (lo + hi) / 2
      if (times(mid) <= t) then
        lo = mid
      else
        hi = mid
      end if
    end do
    k = lo
  end function segment
end module impact1d_forcing
