/PROG  ARC_SEAM
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "fillet weld 1";
PROG_SIZE	= 2310;
CREATE		= DATE 24-03-11  TIME 08:12:40;
MODIFIED	= DATE 24-03-12  TIME 14:02:16;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 11;
MEMORY_SIZE	= 2750;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/APPL
/MN
   1:  UFRAME_NUM=3 ;
   2:  UTOOL_NUM=3 ;
   3:J P[1] 100% CNT100    ;
   4:L P[2] 1000mm/sec FINE    ;
   5:  Weave Sine[1] ;
   6:L P[3] WELD_SPEED CNT100    
    :  Arc Start[3]    ;
   7:L P[4] WELD_SPEED CNT100    ;
   8:C P[5]    
    :  P[6] WELD_SPEED CNT100    ;
   9:L P[7] 8mm/sec FINE    
    :  Arc End[3]    ;
  10:  Weave End ;
  11:L P[8] 1000mm/sec CNT100    ;
/POS
P[1]{
   GP1:
	UF : 3, UT : 3,		CONFIG : 'F U T, 0, 0, 0',
	X =    99.206  mm,	Y =   370.669  mm,	Z =   109.267  mm,
	W =  -156.885 deg,	P =   -25.566 deg,	R =   173.875 deg
};
P[2]{
   GP1:
	UF : 3, UT : 3,		CONFIG : 'F U T, 0, 0, 0',
	X =   136.371  mm,	Y =   305.296  mm,	Z =     1.195  mm,
	W =  -158.718 deg,	P =   -26.007 deg,	R =   173.992 deg
};
P[3]{
   GP1:
	UF : 3, UT : 3,		CONFIG : 'F U T, 0, 0, 0',
	X =   146.729  mm,	Y =   288.836  mm,	Z =   -21.915  mm,
	W =  -159.146 deg,	P =   -26.070 deg,	R =   173.951 deg
};
P[4]{
   GP1:
	UF : 3, UT : 3,		CONFIG : 'F U T, 0, 0, 0',
	X =   147.766  mm,	Y =   202.771  mm,	Z =    -1.308  mm,
	W =  -161.662 deg,	P =   -25.977 deg,	R =   172.591 deg
};
P[5]{
   GP1:
	UF : 3, UT : 3,		CONFIG : 'F U T, 0, 0, 0',
	X =   147.676  mm,	Y =   122.684  mm,	Z =    19.900  mm,
	W =  -164.408 deg,	P =   -25.888 deg,	R =   172.130 deg
};
P[6]{
   GP1:
	UF : 3, UT : 3,		CONFIG : 'F U T, 0, 0, 0',
	X =   146.035  mm,	Y =    34.181  mm,	Z =    45.359  mm,
	W =  -166.635 deg,	P =   -25.472 deg,	R =   171.419 deg
};
P[7]{
   GP1:
	UF : 3, UT : 3,		CONFIG : 'F U T, 0, 0, 0',
	X =   145.539  mm,	Y =   -30.023  mm,	Z =    66.789  mm,
	W =  -169.292 deg,	P =   -24.896 deg,	R =   171.140 deg
};
P[8]{
   GP1:
	UF : 3, UT : 3,		CONFIG : 'F U T, 0, 0, 0',
	X =    97.573  mm,	Y =     5.921  mm,	Z =   207.023  mm,
	W =  -169.684 deg,	P =   -24.970 deg,	R =   172.017 deg
};
/END
